"""ex03 submission: logarithmic decrement over N cycles not divided by N."""
import numpy as np
from scipy.signal import find_peaks


def _peaks(t, y):
    t, y = np.asarray(t), np.asarray(y)
    # rough period from the upward zero crossings of the first second, then peaks at least 0.7 periods apart
    up = np.where((y[:-1] < 0) & (y[1:] >= 0))[0]
    period = np.median(np.diff(t[up[:6]]))
    idx, _ = find_peaks(y, distance=int(0.7 * period / (t[1] - t[0])))
    return t[idx], y[idx]


def natural_frequency(t, y, cycles):
    tp, _ = _peaks(t, y)
    return 2 * np.pi * cycles / (tp[cycles] - tp[0])


def damping_ratio(t, y, cycles):
    _, yp = _peaks(t, y)
    return np.log(yp[0] / yp[cycles]) / (2 * np.pi)


def cart_mass(omega_bare, omega_weighted, m_w):
    return m_w * omega_weighted**2 / (omega_bare**2 - omega_weighted**2)


def stiffness(omega_bare, m_c):
    return omega_bare**2 * m_c


def damping_coefficient(zeta, m_c, omega):
    return 2 * zeta * m_c * omega


def identify_cart(t_bare, y_bare, t_w, y_w, m_w):
    wc = natural_frequency(t_bare, y_bare, 5)
    zc = damping_ratio(t_bare, y_bare, 5)
    ww = natural_frequency(t_w, y_w, 5)
    m_c = cart_mass(wc, ww, m_w)
    return np.array([m_c, stiffness(wc, m_c), damping_coefficient(zc, m_c, wc)])
