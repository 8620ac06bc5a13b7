r"""Upper envelopes (the role of MATLAB's ``ucover``): a stable, minimum-phase, biproper weight
whose magnitude covers given data, one peaking section per resonance of the data."""
from __future__ import annotations

import numpy as np

from ..errors import ModelError, SolverError
from ._magnitude import MagnitudeFit, _zpk_ss


def _peaking(w0: float, ratio: float, zeta: float):
    """Zeros and poles of :math:`(s^2 + 2\\zeta\\omega_0 s + \\omega_0^2)/(s^2 + 2\\zeta_p\\omega_0 s +
    \\omega_0^2)`, :math:`\\zeta_p = \\zeta/\\text{ratio}`: 1 far from :math:`\\omega_0`, ``ratio`` at it."""
    def roots(z):
        return np.roots([1.0, 2.0 * z * w0, w0 * w0]).astype(complex)
    return roots(zeta), roots(zeta / ratio)


def fit_envelope(omega, mag, *, floor: float = 0.02, max_sections: int = 6) -> MagnitudeFit:
    r"""A stable, minimum-phase, biproper :math:`\hat W` whose magnitude bounds ``mag`` from above.

    The weight that covers a spread of frequency responses (the role of
    MATLAB's ``ucover``): :math:`|\hat W(j\omega_k)| \ge \text{mag}_k` at every
    given frequency, and as close to it as a few sections allow.  Lightly damped
    peaks (the resonances of a structure) are what a low-order magnitude fit
    such as :func:`fit_magnitude` smooths away; here each peak of the data gets
    its own peaking section,

    .. math::
        \hat W(s) = g\,\frac{s + a}{s + b} \prod_i \frac{s^2 + 2\zeta_i\omega_i s + \omega_i^2}
                                   {s^2 + 2(\zeta_i/r_i)\,\omega_i s + \omega_i^2},

    where each section is 1 far from :math:`\omega_i` and :math:`r_i > 1` at
    it, and the first-order factor lets the two ends differ.  The
    :math:`3n + 3` parameters minimise the mean squared log error to
    :math:`\max(\text{mag}, \text{floor}\cdot\max\text{mag})` with undershoot
    penalised 3000 times more than overshoot (least squares, a simplex search,
    least squares again); the gain
    is then raised so that no frequency is undershot.

    Parameters
    ----------
    omega : array_like
        Positive frequencies (rad/s), increasing.
    mag : array_like
        Non-negative magnitudes, not all zero.
    floor : float
        Relative level below which the data are not followed (``mag`` that
        falls to zero, as a spread does beyond the last resonance, would ask
        for an infinite slope).  In [0, 1).
    max_sections : int
        Largest number of peaking sections: one for each of the most prominent
        peaks, and those left over a second one for the highest peaks (a
        spread's peak is often flat-topped, which one section cannot follow).

    Returns
    -------
    MagnitudeFit
        ``error`` is the largest :math:`\log(|\hat W|/\max(\text{mag}, \text{floor}\cdot\max\text{mag}))`
        over the data: how loose the cover is where it is loosest (0 = tight).

    Raises
    ------
    ModelError
        Empty or mismatched data, non-positive frequencies, negative or all-zero
        magnitudes, ``floor`` outside [0, 1).

    Examples
    --------
    A lightly damped resonance (damping ratio 0.02) between a low-frequency
    level of 1.1 and a high-frequency one of 0.1: covered everywhere, and
    within 30 % at the peak.

    >>> import numpy as np
    >>> w = np.logspace(-1, 2, 300)
    >>> mag = np.abs(0.1 + 1 / ((1j * w) ** 2 + 0.04j * w + 1))
    >>> fit = fit_envelope(w, mag)
    >>> bool(np.all(np.abs(fit(w)) >= mag)), bool(np.abs(fit(w)).max() < 1.3 * mag.max())
    (True, True)
    """
    omega, env, target = _envelope_data(omega, mag, floor, max_sections)
    model = _Envelope(omega, target)
    p0, lower, upper = _initial(omega, env, target, model.base, max_sections)
    return model.cover(model.optimise(p0, lower, upper), omega)


def _envelope_data(omega, mag, floor, max_sections):
    """The data of :func:`fit_envelope` checked and sorted: ``(omega, env, log env)`` with
    ``env = max(mag, floor * max(mag))``."""
    omega = np.asarray(omega, dtype=float).ravel()
    mag = np.asarray(mag, dtype=float).ravel()
    if omega.size != mag.size or omega.size < 3:
        raise ModelError(f"envelope fit: omega and mag must have equal length of at least 3 (got {omega.size} "
                         f"and {mag.size})")
    if not (np.all(np.isfinite(omega)) and np.all(omega > 0)):
        raise ModelError("envelope fit: frequencies must be positive and finite")
    if not (np.all(np.isfinite(mag)) and np.all(mag >= 0) and mag.max() > 0):
        raise ModelError("envelope fit: magnitudes must be finite, non-negative and not all zero")
    if not (isinstance(floor, (int, float, np.integer, np.floating)) and 0 <= floor < 1):
        raise ModelError(f"envelope fit: floor must lie in [0, 1), got {floor!r}")
    if isinstance(max_sections, (bool, np.bool_)) or not isinstance(max_sections, (int, np.integer)) \
            or max_sections < 0:
        raise ModelError(f"envelope fit: max_sections must be a non-negative integer, got {max_sections!r}")
    order = np.argsort(omega)
    omega, mag = omega[order], mag[order]
    env = np.maximum(mag, floor * mag.max())
    if not np.all(env > 0):
        raise ModelError("envelope fit: magnitudes that are zero need floor > 0")
    return omega, env, np.log(env)


class _Envelope:
    r"""The cover's log magnitude on the data as a function of its parameters ``p``: the log
    gain relative to the data's median, :math:`\log a`, :math:`\log b`, then per peaking section
    :math:`\log\omega_i`, :math:`\log(r_i - 1)` and :math:`\log\zeta_i`."""

    def __init__(self, omega, target):
        self.s = 1j * omega
        self.target = target
        self.base = float(np.exp(np.median(target)))

    def unpack(self, p):
        """``(g, (a, b), [(w0, r, zeta), ...])`` of the parameter vector ``p``."""
        g, a, b = self.base * np.exp(p[0]), float(np.exp(p[1])), float(np.exp(p[2]))
        secs = [(float(np.exp(p[3 + 3 * k])), 1.0 + float(np.exp(p[4 + 3 * k])), float(np.exp(p[5 + 3 * k])))
                for k in range((len(p) - 3) // 3)]
        return g, (a, b), secs

    def logmag(self, p):
        """:math:`\\log|\\hat W(j\\omega)|` on the data's frequencies."""
        s = self.s
        g, (a, b), secs = self.unpack(p)
        out = np.log(g) + np.log(np.abs((s + a) / (s + b)))
        for w0, r, z in secs:
            out += np.log(np.abs((s * s + 2 * z * w0 * s + w0 * w0) / (s * s + 2 * (z / r) * w0 * s + w0 * w0)))
        return out

    def residuals(self, p):
        """The log error to the data, undershoot weighted 3000 times more (in the squares) than overshoot."""
        d = self.logmag(p) - self.target
        return np.where(d < 0.0, np.sqrt(3000.0) * d, d) / np.sqrt(d.size)

    def cost(self, p, lower, upper) -> float:
        """The sum of the squared residuals at ``p`` clipped to the bounds."""
        return float(np.sum(self.residuals(np.clip(p, lower, upper)) ** 2))

    def optimise(self, p0, lower, upper):
        """The parameters from ``p0``: least squares, a simplex search from there, least squares again."""
        from scipy.optimize import least_squares, minimize
        with np.errstate(all="ignore"):
            # the cost is smooth but not convex (the sections trade places): least squares from the
            # peaks, a simplex search from there, and least squares again
            p = least_squares(self.residuals, p0, method="trf", x_scale="jac", max_nfev=400 * p0.size,
                              bounds=(lower, upper)).x
            p = np.clip(minimize(self.cost, p, args=(lower, upper), method="Nelder-Mead",
                                 options={"maxfev": 600 * p.size, "xatol": 1e-6, "fatol": 1e-12}).x, lower, upper)
            p = least_squares(self.residuals, p, method="trf", x_scale="jac", max_nfev=400 * p.size,
                              bounds=(lower, upper)).x
        if not np.isfinite(self.cost(p, lower, upper)):
            raise SolverError("envelope fit: the fit did not converge to finite values")
        return p

    def cover(self, p, omega) -> MagnitudeFit:
        """The weight of the parameters ``p``, its gain raised so that no frequency is undershot."""
        g, (a, b), secs = self.unpack(p)
        # no frequency undershot: raise the gain by the largest shortfall (and a hair, for rounding)
        g *= float(np.exp(max(0.0, np.max(self.target - self.logmag(p))))) * (1.0 + 1e-7)
        zeros, poles = [complex(-a)], [complex(-b)]
        for w0, r, z in secs:
            zz, pp = _peaking(w0, r, z)
            zeros += list(zz)
            poles += list(pp)
        zeros, poles = np.array(zeros, dtype=complex), np.array(poles, dtype=complex)
        fit = MagnitudeFit(_zpk_ss(zeros, poles, g), len(poles), 0.0, zeros, poles, g)
        fit.error = float(np.max(np.log(np.abs(fit(omega))) - self.target))
        return fit


def _initial(omega, env, target, base: float, max_sections):
    """Start and bounds of the parameters: a first-order factor across the band and a peaking
    section on each of the most prominent peaks (two on the highest, while sections are left)."""
    from scipy.signal import find_peaks
    # the peaks that stand out from their surroundings by at least 20 %
    idx, props = find_peaks(target, prominence=np.log(1.2))
    keep = np.argsort(props["prominences"])[::-1][:int(max_sections)] if idx.size else []
    idx = np.sort(idx[keep]) if idx.size else idx
    lo = float(np.exp(np.percentile(target, 10)))
    mid = float(np.sqrt(omega[0] * omega[-1]))
    p0 = [np.log(lo / base), np.log(mid), np.log(mid)]
    lw = np.log(omega)
    seeds = []
    for i in idx:
        # the peak's width: where the data fall to half the peak (in log)
        half = np.log(env[i]) - 0.5 * (np.log(env[i]) - np.log(lo))
        left = np.flatnonzero(target[:i] < half)
        right = np.flatnonzero(target[i:] < half)
        width = float(np.clip(min(lw[i] - lw[left[-1]] if left.size else 1.0,
                                  lw[i + right[0]] - lw[i] if right.size else 1.0), 1e-3, 1.0))
        seeds.append((lw[i], max(env[i] / lo - 1.0, 0.2), width, float(target[i])))
    # a spread's peak is often flat-topped (different pairs of systems are widest across it), which
    # one section cannot follow: the highest peaks get two sections, either side, while there is room
    doubled = set(np.argsort([-h for *_, h in seeds])[:max(0, int(max_sections) - len(seeds))])
    p0 = list(p0)
    for k, (c, r, width, _) in enumerate(seeds):
        pair = k in doubled
        rr = np.sqrt(r) if pair else r
        for shift in ((-0.5 * width, 0.5 * width) if pair else (0.0,)):
            # a peaking section is about ratio/e**0.5 high at (1 +- zeta_p) w0: zeta_p ~ width / 2
            p0 += [c + shift, np.log(rr), np.log(float(np.clip(0.5 * width * (1.0 + rr), 1e-3, 10.0)))]
    nsec = (len(p0) - 3) // 3
    p0 = np.array(p0)
    span = (lw[0] - 2 * np.log(10.0), lw[-1] + 2 * np.log(10.0))
    lower = [-np.inf, span[0], span[0]] + [span[0], np.log(1e-3), np.log(1e-3)] * nsec
    upper = [np.inf, span[1], span[1]] + [span[1], np.log(1e6), np.log(10.0)] * nsec
    p0 = np.clip(p0, np.array(lower) + 1e-9, np.array(upper) - 1e-9)
    return p0, lower, upper
