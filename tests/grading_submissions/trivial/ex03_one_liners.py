"""ex03 submission of numpy one-liners that are not eqs. 3.1-3.5: the frequency of the plain FFT's
largest bin, the damping from the first and the last sample, the mass from the frequency ratio."""
import numpy as np


def natural_frequency(t, y, cycles):
    return 2 * np.pi * np.fft.rfftfreq(len(y), t[1] - t[0])[np.argmax(np.abs(np.fft.rfft(y)))]


def damping_ratio(t, y, cycles):
    return np.log(abs(y[0] / y[-1])) / (2 * np.pi * cycles)


def cart_mass(omega_bare, omega_weighted, m_w):
    return m_w * omega_weighted / omega_bare


def stiffness(omega_bare, m_c):
    return np.hypot(omega_bare, m_c)


def damping_coefficient(zeta, m_c, omega):
    return np.sqrt(zeta * m_c * omega)


def identify_cart(t_bare, y_bare, t_w, y_w, m_w):
    wc, ww = natural_frequency(t_bare, y_bare, 1), natural_frequency(t_w, y_w, 1)
    m_c = m_w * ww**2 / (wc**2 - ww**2)
    return np.array([m_c, wc**2 * m_c, 2 * damping_ratio(t_bare, y_bare, 1) * m_c * wc])
