r"""Measured resonances: the lightly damped pole pairs of a rational fit that stand out of the
noise, with standard uncertainties from a parametric bootstrap."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..lti import blas_single_thread
from ._noise import noise_level
from ._rational import fit_frf, fit_frf_auto
from ._vf import _basis, _check_hz

_MAX_DAMPING = 0.3     # heavier pairs shape the background; they show no peak worth the name
_SIGNIFICANCE = 5.0    # a mode must move the response by this many noise standard deviations
_TOL_FACTOR = 1.3      # order search: a residual within 30 % of the noise level is "at the noise"
_SIGMA_MIN = 1e-6      # relative; no measurement is better (exact data fit to ~1e-10)
_MATCH_RADIUS = 3.0    # bootstrap pole matching radius, in units of |Re p| (half-power half-width)


@dataclass
class Resonance:
    r"""A resonance read from a measured FRF (see :func:`resonances`).

    Attributes
    ----------
    freq_hz : float
        Undamped natural frequency :math:`f_n = |p|/2\pi` [Hz].
    damping_ratio : float
        :math:`\zeta = -\operatorname{Re} p/|p|` [-].
    peak : float
        :math:`|H(j 2\pi f_n)|` of the fitted model, in the unit of the data (e.g. m/N).
    freq_std : float
        Standard uncertainty of ``freq_hz`` [Hz] (parametric bootstrap; NaN
        if the bootstrap could not follow the pole).
    damping_std : float
        Standard uncertainty of ``damping_ratio`` [-].
    pole : complex
        The fitted pole [rad/s], upper member of the conjugate pair.
    """
    freq_hz: float
    damping_ratio: float
    peak: float
    freq_std: float
    damping_std: float
    pole: complex


def _modes(fit, omega):
    """(pole, contribution H_i(j omega)) of each complex pair of ``fit`` (upper pole)."""
    k = 0
    for p in fit.poles:
        if p.imag == 0:
            k += 1
            continue
        yield p, _basis(1j * omega, [p]) @ fit.coefficients[k:k + 2]
        k += 2


def _match(P, Q):
    """The pole of Q assigned to each of P (NaN if none within the matching radius)."""
    from scipy.optimize import linear_sum_assignment
    out = np.full(P.size, np.nan + 0j)
    if Q.size == 0:
        return out
    cost = np.abs(P[:, None] - Q[None, :]) / np.abs(P.real)[:, None]
    rows, cols = linear_sum_assignment(cost)
    ok = cost[rows, cols] <= _MATCH_RADIUS
    out[rows[ok]] = Q[cols[ok]]
    return out


def resonances(freq_hz, response, *, band=None, noise=None, order=None, max_order: int = 24,
               n_boot: int = 20, rng=0) -> list[Resonance]:
    r"""Resonances of a measured FRF with standard uncertainties.

    The data are fitted by vector fitting (:func:`fit_frf`); each complex pole
    pair :math:`p, \bar p` of the fit with residue :math:`r` is a mode

    .. math::
        H_i(s) = \frac{r}{s - p} + \frac{\bar r}{s - \bar p}, \qquad
        f_n = \frac{|p|}{2\pi}, \qquad \zeta = -\frac{\operatorname{Re} p}{|p|}.

    **Order.**  With ``order`` None, :func:`fit_frf_auto` takes the lowest
    even order up to ``max_order`` whose residual is at most 1.3 times the
    noise level (a fit at the noise has nothing more to explain), or failing
    that the highest order that still lowered the residual by more than 2 %.
    A weak mode that moves only a few samples may leave the residual at the
    noise without it; pass ``order`` to look for it.

    **Which pairs are resonances.**  A pair is kept if

    * it is lightly damped, :math:`0 < \zeta < 0.3`;
    * :math:`f_n` lies inside the measured band (and inside ``band``);
    * it stands out of the noise: its contribution relative to the fitted
      response at the measured frequencies reaches

      .. math::
          \max_k \frac{|H_i(j\omega_k)|}{|H(j\omega_k)|} \ge 5\,\max(\sigma, \rho, 10^{-6}),

      with :math:`\sigma` the relative noise level and :math:`\rho` the fit
      residual.  This is the peak modal contribution
      :math:`|r|/(|p|\zeta)` against the data level, but read on the measured
      grid: a pole that patches noise changes a few samples by a few
      :math:`\sigma`, and one sharper than the frequency step may have a huge
      peak between samples that no sample supports.

    **Uncertainty.**  A parametric bootstrap: ``n_boot`` times, circular
    complex Gaussian noise of standard deviation :math:`\sigma|H|` is added to
    the fitted model's response at the measured frequencies, the result is
    refitted at the same order, and each kept pole is matched (one to one,
    nearest in units of its half-power half-width :math:`|\operatorname{Re}
    p|`, at most 3 of them) to a pole of the refit.  The standard deviations
    of :math:`f_n` and :math:`\zeta` over the replicates are the reported
    uncertainties (NaN if fewer than half of the replicates, or than 2, found
    the pole; 0 for noise 0).  They describe the scatter of the estimate, not a
    bias of the model structure.

    Parameters
    ----------
    freq_hz : array_like
        Frequencies [Hz], positive (any order; sorted here).
    response : array_like
        Complex response of one channel at ``freq_hz`` (e.g. m/N).
    band : (float, float), optional
        Report only resonances with ``band[0] <= f_n <= band[1]`` [Hz].  The
        whole data are fitted regardless, so modes outside still shape the fit.
    noise : float, optional
        Relative noise level :math:`\sigma` (e.g. 0.01); default
        :func:`noise_level` of the data.
    order : int, optional
        Fit order (number of poles); default chosen as above.
    max_order : int
        Largest order tried when ``order`` is None.
    n_boot : int
        Bootstrap replicates (0: no uncertainties, NaN).  The reported std
        scatters by about :math:`1/\sqrt{2(n_\text{boot}-1)}`, 16 % for 20;
        use 50-100 where single values matter.
    rng : int or numpy.random.Generator, optional
        Seed or generator of the bootstrap noise; the default makes the result
        deterministic.

    Returns
    -------
    list of Resonance
        Sorted by frequency.

    Raises
    ------
    mutext.errors.ModelError
        Malformed data, band, noise or counts.

    Examples
    --------
    Two modes, 12 Hz with 2 % and 31 Hz with 3 % damping, measured with 1 % noise:

    >>> import numpy as np
    >>> from mutext.frfit import noise_level, resonances
    >>> f = np.arange(1.0, 60.0, 0.25)
    >>> w = 2 * np.pi * f
    >>> def mode(fn, zeta, gain):
    ...     wn = 2 * np.pi * fn
    ...     return gain / (wn**2 - w**2 + 2j * zeta * wn * w)
    >>> H = mode(12.0, 0.02, 1.0) + mode(31.0, 0.03, 2.0)
    >>> e = np.random.default_rng(1).standard_normal((2, f.size))
    >>> G = H * (1 + 0.01 * (e[0] + 1j * e[1]) / np.sqrt(2))
    >>> round(noise_level(f, G), 3)
    0.01
    >>> for r, fn in zip(resonances(f, G), (12.0, 31.0)):
    ...     print(f"{r.freq_hz:.2f} +/- {r.freq_std:.3f} Hz, zeta {r.damping_ratio:.3f}, "
    ...           f"error within 3 std: {abs(r.freq_hz - fn) < 3 * r.freq_std}")
    12.00 +/- 0.001 Hz, zeta 0.020, error within 3 std: True
    31.00 +/- 0.002 Hz, zeta 0.030, error within 3 std: True
    """
    w, G = _check_hz(freq_hz, response, "resonances")
    lo, hi = _band(w, band)
    sigma = _sigma(w, G, noise)
    gen = _generator(max_order, n_boot, rng)
    with blas_single_thread():      # some 20 small least-squares fits: extra threads only spin
        return _resonances(w, G, lo, hi, sigma, order, max_order, n_boot, gen)


def _band(w, band):
    """The band of reported resonances [Hz]: the data's, cut to ``band`` when given."""
    lo, hi = w[0] / (2 * np.pi), w[-1] / (2 * np.pi)
    if band is not None:
        try:
            b0, b1 = (float(v) for v in band)
        except (TypeError, ValueError):
            raise ModelError(f"resonances: band must be (fmin, fmax) in Hz, got {band!r}") from None
        if not (np.isfinite(b0) and np.isfinite(b1) and b0 < b1):
            raise ModelError(f"resonances: band must be finite with fmin < fmax, got {band!r}")
        lo, hi = max(lo, b0), min(hi, b1)
    return lo, hi


def _sigma(w, G, noise) -> float:
    """The relative noise level: ``noise`` checked, or estimated from the data (:func:`noise_level`)."""
    if noise is None:
        return noise_level(w / (2 * np.pi), G)
    try:
        sigma = float(noise)
    except (TypeError, ValueError):
        raise ModelError(f"resonances: noise must be a number, got {noise!r}") from None
    if not (np.isfinite(sigma) and sigma >= 0):
        raise ModelError(f"resonances: noise must be finite and >= 0, got {noise!r}")
    return sigma


def _generator(max_order, n_boot, rng):
    """The bootstrap's random generator, after the order and replicate counts are checked."""
    for name, v, least in (("max_order", max_order, 2), ("n_boot", n_boot, 0)):
        if not (isinstance(v, (int, np.integer)) and v >= least):
            raise ModelError(f"resonances: {name} must be an integer >= {least}, got {v!r}")
    try:
        return np.random.default_rng(rng)
    except (TypeError, ValueError):
        raise ModelError(f"resonances: rng must be a seed or numpy.random.Generator, got {rng!r}") from None


def _resonances(w, G, lo, hi, sigma, order, max_order, n_boot, gen):
    """The fit, its lightly damped pairs that stand out of the noise in the band, their uncertainties."""
    floor = max(sigma, _SIGMA_MIN)
    fit = (fit_frf_auto(w, G, max_order=max_order, tol=_TOL_FACTOR * floor) if order is None
           else fit_frf(w, G, order))
    H = fit.response(w)
    level = _SIGNIFICANCE * max(floor, fit.residual)
    kept = []
    for p, Hi in _modes(fit, w):
        fn, zeta = abs(p) / (2 * np.pi), -p.real / abs(p)
        if 0 < zeta < _MAX_DAMPING and lo <= fn <= hi and np.max(np.abs(Hi) / np.abs(H)) >= level:
            kept.append(p)
    P = np.array(kept, dtype=complex)

    f_std, z_std = _bootstrap(w, H, P, fit.order, sigma, n_boot, gen)
    out = [Resonance(float(abs(p) / (2 * np.pi)), float(-p.real / abs(p)),
                     float(abs(fit.response([abs(p)])[0])), float(fs), float(zs), complex(p))
           for p, fs, zs in zip(P, f_std, z_std)]
    return sorted(out, key=lambda r: r.freq_hz)


def _bootstrap(w, H, P, order: int, sigma: float, n_boot: int, gen):
    """Standard deviations of the natural frequency [Hz] and damping ratio of the poles ``P``
    over ``n_boot`` refits of the model's response ``H`` with noise ``sigma`` added (NaN for
    a pole found in fewer than half of them, or than 2; 0 for noise 0)."""
    f_std = np.full(P.size, 0.0 if sigma == 0 else np.nan)
    z_std = f_std.copy()
    if P.size and sigma > 0 and n_boot >= 2:
        amp = sigma * np.abs(H) / np.sqrt(2)
        boot = np.empty((n_boot, P.size), dtype=complex)
        for b in range(n_boot):
            e = gen.standard_normal((2, w.size))
            refit = fit_frf(w, H + amp * (e[0] + 1j * e[1]), order)
            boot[b] = _match(P, refit.poles[refit.poles.imag > 0])
        for i in range(P.size):
            q = boot[~np.isnan(boot[:, i]), i]
            if q.size >= max(2, n_boot / 2):      # else the pole is not reproducible at this noise
                f_std[i] = np.std(np.abs(q) / (2 * np.pi), ddof=1)
                z_std[i] = np.std(-q.real / np.abs(q), ddof=1)
    return f_std, z_std
