r"""Parameter identification from free-decay records (thesis sec. 3.3.2, eqs. 3.1-3.6).

A cart is released from an initial displacement with its neighbours clamped,
so it moves as a single degree of freedom :math:`m\ddot x + c\dot x + kx = 0`.
From two peaks :math:`N` cycles apart (times :math:`t_1, t_2`, amplitudes
:math:`y_1, y_2`):

.. math::
    \omega = \frac{2\pi N}{t_2 - t_1}\quad(3.1),\qquad
    \zeta = \frac{1}{2\pi N}\ln\frac{y_1}{y_2}\quad(3.2).

Repeating the test with a known added mass :math:`m_w` separates mass and
stiffness:

.. math::
    m_c = \frac{m_w\,\omega_w^2}{\omega_c^2 - \omega_w^2}\quad(3.3),\qquad
    k_{eq} = \omega_c^2 m_c\quad(3.4),\qquad c = 2\zeta m_c\omega_c\quad(3.5),

(the thesis prints :math:`\omega_c^2` in the numerator of (3.3); that expression
equals :math:`m_c + m_w`, not :math:`m_c`, since
:math:`\omega_c^2 = k/m_c` and :math:`\omega_w^2 = k/(m_c + m_w)`), and a damper
attached to the weighted cart follows from
:math:`c_d = 2(m_c + m_w)\zeta_d\omega_d - c_m` (3.6).

Eq. (3.1) measures the *damped* frequency :math:`\omega_d = \omega_n\sqrt{1-\zeta^2}`.
The thesis uses it as :math:`\omega_n`; :func:`decay_estimate` returns both,
and the cart formulas take ``correct_damping=True`` to use
:math:`\omega_n`.  Eq. (3.2) is the logarithmic decrement, exact for
viscous damping only approximately for the thesis's form (the exact relation
is :math:`\delta = 2\pi\zeta/\sqrt{1-\zeta^2}`); both are reported.

All quantities SI (s, m, kg, N/m, N s/m).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._validation import Real, validate_params
from .errors import ModelError

__all__ = ["simulate_free_decay", "decay_peaks", "DecayEstimate", "decay_estimate", "CartParameters",
           "cart_parameters", "damper_coefficient", "identify_three_mass"]


@validate_params({"m": Real(lo=0, closed="neither"), "k": Real(lo=0, closed="neither"), "c": Real(lo=0)})
def simulate_free_decay(m: float, k: float, c: float, x0: float = 0.025, duration: float = 3.0,
                        fs: float = 1000.0, noise: float = 0.0, rng=None):
    """Sampled free decay of ``m x'' + c x' + k x = 0`` from rest at ``x0`` (m).

    Returns ``(t, y)`` in s and m; ``noise`` is the standard deviation (m) of
    white measurement noise (an encoder or sensor).

    Parameters
    ----------
    m : float
        Mass (kg).
    k : float
        Stiffness (N/m).
    c : float
        Viscous damping (N s/m), below critical.
    x0 : float, optional
        Initial displacement (m).
    duration : float, optional
        Record length (s).
    fs : float, optional
        Sampling rate (Hz).
    noise : float, optional
        Standard deviation of white measurement noise (m).
    rng : numpy.random.Generator or int, optional
        Random generator or seed of the noise.

    Examples
    --------
    >>> from mutext.sysid import simulate_free_decay, decay_estimate
    >>> t, y = simulate_free_decay(m=2.0, k=800.0, c=1.6)        # 20 rad/s, 2 % damping
    >>> est = decay_estimate(t, y)
    >>> round(est.omega_n, 2), round(est.zeta_exact, 4)
    (20.0, 0.02)
    """
    wn = np.sqrt(k / m)
    z = c / (2.0 * np.sqrt(k * m))
    if z >= 1:
        raise ModelError(f"free decay: damping ratio {z:.3g} >= 1, the record would not oscillate")
    wd = wn * np.sqrt(1.0 - z * z)
    t = np.arange(int(round(duration * fs)) + 1) / fs
    y = x0 * np.exp(-z * wn * t) * (np.cos(wd * t) + z * wn / wd * np.sin(wd * t))
    if noise > 0:
        rng = np.random.default_rng(rng)
        y = y + noise * rng.standard_normal(t.size)
    return t, y


def decay_peaks(t, y):
    """Times and heights of the positive peaks of a decaying oscillation.

    Each peak is refined by a least-squares parabola over a twentieth of a period,
    and peaks lower than five times the noise level (estimated from the
    second difference of the record) are dropped.

    Parameters
    ----------
    t : (N,) array_like
        Increasing sample times (s).
    y : (N,) array_like
        The record (any unit).
    """
    from scipy.signal import find_peaks
    t, y = np.asarray(t, float), np.asarray(y, float)
    if t.ndim != 1 or t.shape != y.shape or t.size < 5:
        raise ModelError("decay record: t and y must be 1-D arrays of the same length (at least 5 samples)")
    if np.any(np.diff(t) <= 0):
        raise ModelError("decay record: time stamps must increase")
    dt = float(np.median(np.diff(t)))
    # white noise dominates the second difference of a well-sampled oscillation
    noise = float(np.std(np.diff(y, 2)) / np.sqrt(6.0))
    tail = y[-max(5, y.size // 10):]
    # period from the spectrum's peak (robust to noise, unlike zero crossings)
    nfft = 1 << int(np.ceil(np.log2(8 * y.size)))
    spec = np.abs(np.fft.rfft((y - np.mean(tail)) * np.hanning(y.size), nfft))
    freqs = np.fft.rfftfreq(nfft, dt)
    spec[freqs < 1.5 / (t[-1] - t[0])] = 0.0  # fewer than 1.5 cycles in the record: leakage, not a mode
    f = freqs[int(np.argmax(spec))]
    if f <= 0:
        raise ModelError("decay record: no oscillation found")
    per = max(3, int(round(1.0 / (f * dt))))
    idx, _ = find_peaks(y, distance=max(1, int(0.7 * per)), height=5 * noise + 1e-300)
    # least-squares parabola over +/- 1/20 period around each peak averages the noise
    h = max(1, per // 20)
    idx = idx[(idx >= h) & (idx < y.size - h)]
    tp, yp = [], []
    for i in idx:
        tt = t[i - h:i + h + 1] - t[i]
        c2, c1, c0 = np.polyfit(tt, y[i - h:i + h + 1], 2)
        d = -c1 / (2 * c2) if c2 < 0 else 0.0
        d = float(np.clip(d, tt[0], tt[-1]))
        tp.append(t[i] + d)
        yp.append(c0 + c1 * d + c2 * d * d)
    return np.array(tp), np.array(yp)


@dataclass
class DecayEstimate:
    """Frequency and damping from a free-decay record.

    ``omega`` is eq. (3.1) (the damped frequency, rad/s), ``zeta`` eq. (3.2);
    ``omega_n`` and ``zeta_exact`` undo the two approximations.

    Attributes
    ----------
    omega : float
        Damped frequency (rad/s), eq. (3.1).
    zeta : float
        Damping ratio from the logarithmic decrement, eq. (3.2).
    omega_n : float
        Undamped natural frequency (rad/s).
    zeta_exact : float
        Damping ratio without the small-damping approximation.
    cycles : int
        Number of periods between the two peaks used.
    peaks : int
        Number of clear peaks found in the record.
    """
    omega: float
    zeta: float
    omega_n: float
    zeta_exact: float
    cycles: int
    peaks: int


def decay_estimate(t, y, cycles: int | None = None) -> DecayEstimate:
    """Eqs. (3.1)-(3.2) from the first peak and the peak ``cycles`` later.

    By default ``cycles`` spans as many peaks as stand clear of the noise.

    Parameters
    ----------
    t : (N,) array_like
        Increasing sample times (s).
    y : (N,) array_like
        The record (any unit).
    cycles : int, optional
        Number of periods between the two peaks used.
    """
    tp, yp = decay_peaks(t, y)
    if tp.size < 2:
        raise ModelError(f"decay record: found {tp.size} clear peak(s); need at least two "
                         "(record too short, too noisy or not oscillating)")
    N = tp.size - 1 if cycles is None else int(cycles)
    if not 1 <= N <= tp.size - 1:
        raise ModelError(f"decay record: cycles={cycles} but only {tp.size} clear peaks were found")
    omega = 2 * np.pi * N / (tp[N] - tp[0])
    delta = np.log(yp[0] / yp[N]) / N
    zeta = delta / (2 * np.pi)
    zeta_exact = delta / np.sqrt(4 * np.pi ** 2 + delta ** 2)
    omega_n = omega / np.sqrt(1 - zeta_exact ** 2)
    return DecayEstimate(float(omega), float(zeta), float(omega_n), float(zeta_exact), N, int(tp.size))


@dataclass
class CartParameters:
    """Cart mass ``m_c`` (kg), equivalent stiffness ``k_eq`` (N/m) and damping ``c`` (N s/m).

    Attributes
    ----------
    m_c : float
        Cart mass (kg).
    k_eq : float
        Equivalent stiffness seen by the cart (N/m).
    c : float
        Viscous damping of the cart (N s/m).
    cart : DecayEstimate
        The bare cart's decay.
    weighted : DecayEstimate
        The decay with the added mass.
    """
    m_c: float
    k_eq: float
    c: float
    cart: DecayEstimate
    weighted: DecayEstimate


def cart_parameters(cart: DecayEstimate, weighted: DecayEstimate, m_w: float,
                    correct_damping: bool = False) -> CartParameters:
    """Eqs. (3.3)-(3.5) from the bare-cart and weighted-cart decays.

    ``correct_damping=False`` reproduces the thesis (damped frequency and the
    approximate decrement); ``True`` uses the exact undamped quantities.

    Parameters
    ----------
    cart : DecayEstimate
        Decay of the bare cart.
    weighted : DecayEstimate
        Decay of the cart with ``m_w`` added.
    m_w : float
        The added mass (kg).
    correct_damping : bool, optional
        Use the undamped frequencies and exact damping ratios instead of the thesis's approximations.
    """
    wc, ww = (cart.omega_n, weighted.omega_n) if correct_damping else (cart.omega, weighted.omega)
    zc = cart.zeta_exact if correct_damping else cart.zeta
    if not wc > ww:
        raise ModelError(f"the weighted cart must oscillate more slowly than the bare cart "
                         f"(got {ww:.4g} rad/s vs {wc:.4g} rad/s)")
    m_c = m_w * ww ** 2 / (wc ** 2 - ww ** 2)
    return CartParameters(float(m_c), float(wc ** 2 * m_c), float(2 * zc * m_c * wc), cart, weighted)


def damper_coefficient(damped: DecayEstimate, m_c: float, m_w: float, c_m: float,
                       correct_damping: bool = False) -> float:
    """Eq. (3.6): the damper's coefficient from a decay of the weighted cart with the damper on.

    Parameters
    ----------
    damped : DecayEstimate
        Decay of the weighted cart with the damper attached.
    m_c : float
        Cart mass (kg).
    m_w : float
        The added mass (kg).
    c_m : float
        The cart's own damping (N s/m), subtracted.
    correct_damping : bool, optional
        Use the undamped frequency and exact damping ratio instead of the thesis's approximations.
    """
    w = damped.omega_n if correct_damping else damped.omega
    z = damped.zeta_exact if correct_damping else damped.zeta
    return float(2 * (m_c + m_w) * z * w - c_m)


def identify_three_mass(rig, m_w: float = 2.0, noise: float = 0.0, rng=0,
                        correct_damping: bool = False, fs: float = 1000.0, duration: float = 3.0,
                        air_damper: float = 0.0):
    """Simulate the identification experiment of thesis sec. 3.3.2 on a rig and identify it.

    Each cart is decayed alone (others clamped: stiffness ``k1``, ``k1 + k2``,
    ``k2 + k3`` for carts 1-3) bare and with ``m_w`` added; cart 3 again with the
    air damper.  The rig's cart masses are its masses minus ``m_w`` (the thesis
    identified them with 2 kg on each cart).

    Parameters
    ----------
    rig : mutext.examples.three_mass.ThreeMass
        The rig to simulate (its fields ``m1..m3``, ``k1..k3``, ``c1..c3``
        and ``with_``), e.g. ``TABLE_3_1``.
    air_damper : float
        The share of ``c3`` (N s/m) due to the air damper, identified by its
        own decay (eq. 3.6); 0 when cart 3 has none.
    m_w : float, optional
        The mass (kg) added to each cart for the second decay.
    noise : float, optional
        Standard deviation (m) of the measurement noise of every record.
    rng : numpy.random.Generator or int, optional
        Random generator or seed of the noise.
    correct_damping : bool, optional
        Use the undamped frequencies and exact damping ratios instead of the thesis's approximations.
    fs : float, optional
        Sampling rate of the records (Hz).
    duration : float, optional
        Length of each record (s).

    Returns
    -------
    identified : ThreeMass
        Parameters assembled as in Table 3.1.
    table : list of dict
        One row per parameter: ``name``, ``true``, ``identified``, ``rel_error``.
    """
    c_air = float(air_damper)
    if not 0.0 <= c_air < rig.c3:
        raise ModelError(f"air_damper must lie in [0, c3 = {rig.c3:.6g}) N s/m, got {air_damper!r}")
    rng = np.random.default_rng(rng)
    carts = [(rig.m1 - m_w, rig.k1, rig.c1), (rig.m2 - m_w, rig.k1 + rig.k2, rig.c2),
             (rig.m3 - m_w, rig.k2 + rig.k3, rig.c3 - c_air)]
    est = []
    for mc, keq, cm in carts:
        if not mc > 0:
            raise ModelError(f"cart mass {mc:.4g} kg: the rig's masses must exceed the added weight {m_w} kg")
        bare = decay_estimate(*simulate_free_decay(mc, keq, cm, noise=noise, rng=rng, fs=fs, duration=duration))
        heavy = decay_estimate(*simulate_free_decay(mc + m_w, keq, cm, noise=noise, rng=rng, fs=fs,
                                                    duration=duration))
        est.append(cart_parameters(bare, heavy, m_w, correct_damping))
    mc3, keq3, cm3 = carts[2]
    damped = decay_estimate(*simulate_free_decay(mc3 + m_w, keq3, cm3 + c_air, noise=noise, rng=rng,
                                                 fs=fs, duration=duration))
    c_d = damper_coefficient(damped, est[2].m_c, m_w, est[2].c, correct_damping) if c_air else 0.0
    k1 = est[0].k_eq
    k2 = est[1].k_eq - k1
    k3 = est[2].k_eq - k2
    ident = rig.with_(m1=est[0].m_c + m_w, m2=est[1].m_c + m_w, m3=est[2].m_c + m_w, k1=k1, k2=k2, k3=k3,
                      c1=est[0].c, c2=est[1].c, c3=est[2].c + c_d)
    table = []
    for name in ("m1", "m2", "m3", "k1", "k2", "k3", "c1", "c2", "c3"):
        a, b = getattr(rig, name), getattr(ident, name)
        table.append({"name": name, "true": a, "identified": b, "rel_error": (b - a) / a})
    return ident, table
