r"""Rational models of measured frequency responses (vector fitting).

A measured FRF :math:`G_k = G(j\omega_k)` is approximated by a stable, strictly
proper rational function in pole-residue form,

.. math::
    H(s) = \sum_{i=1}^{n} \frac{r_i}{s - p_i},

with complex poles in conjugate pairs.  The poles are found by the vector
fitting iteration [GS]_: with the current poles :math:`p_i`, a scaling function
:math:`\sigma(s) = 1 + \sum_i \tilde r_i/(s - p_i)` and the numerator are fitted
by linear least squares from :math:`\sigma(s) G(s) \approx \sum_i r_i/(s-p_i)`;
the zeros of :math:`\sigma` are the new poles (unstable ones are reflected into
the left half plane).  With the poles fixed, the residues are a final linear
least-squares fit.  Each frequency is weighted by :math:`1/|G_k|`, so a response
spanning decades is fitted in relative terms, resonances and antiresonances
alike.

The residual reported is the RMS relative error
:math:`\sqrt{\operatorname{mean}_k |H(j\omega_k) - G_k|^2/|G_k|^2}`: with noisy
data it cannot go below the noise level, and a fit well above it means the
order is too low.

:func:`fit_magnitude` fits a magnitude alone (the D scalings of mu-synthesis,
:mod:`mutext.dk`): the same vector-fitting step (:func:`_relocate`) on
:math:`|D|^2` as a rational function of :math:`\omega^2`, a least-squares fit
of the residues kept positive, and a spectral factorisation to a stable,
minimum-phase :math:`\hat D(s)`.

:func:`resonances` reads the lightly damped pole pairs of such a fit as measured
resonances (natural frequency, damping ratio, peak) with standard
uncertainties from a parametric bootstrap; :func:`noise_level` estimates the
relative noise of the data it needs.

References
----------
.. [GS] B. Gustavsen and A. Semlyen, "Rational approximation of frequency domain
   responses by vector fitting", IEEE Trans. Power Delivery 14(3), 1999.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import control as ct
import numpy as np

from .errors import ModelError, SolverError
from .lti import blas_single_thread, ss

__all__ = ["RationalFit", "Resonance", "MagnitudeFit", "fit_envelope", "fit_frf", "fit_frf_auto", "fit_magnitude",
           "noise_level", "resonances"]


@dataclass
class RationalFit:
    """A stable rational model of one measured channel.

    Attributes
    ----------
    system : control.StateSpace
        Real, stable, strictly proper; one input, one output.
    order : int
        Number of states (poles).
    residual : float
        RMS relative error against the data (see the module docstring).
    omega : numpy.ndarray
        Frequencies of the data [rad/s].
    poles : numpy.ndarray
        The real poles and the upper member of each complex pair.
    notes : list of str
    held_out_residual : float or None
        With few frequencies per state: RMS relative error at every fourth
        frequency of a refit without those points (see :func:`fit_frf`).
    coefficients : numpy.ndarray
        Real coefficients of the pole-residue basis (one per real pole, two per
        pair: the real and imaginary parts of its residue).
    """
    system: ct.StateSpace
    order: int
    residual: float
    omega: np.ndarray = field(repr=False)
    poles: np.ndarray = field(repr=False)
    notes: list = field(default_factory=list)
    coefficients: np.ndarray = field(default=None, repr=False)
    held_out_residual: float | None = None

    def response(self, omega) -> np.ndarray:
        """:math:`H(j\\omega)` of the fitted model.

        Parameters
        ----------
        omega : float or array_like
            Frequencies in rad/s.
        """
        return _eval(self.poles, self.coefficients, np.asarray(omega, float))


def _check_data(omega, response):
    w = np.asarray(omega, dtype=float).ravel()
    G = np.asarray(response, dtype=complex).ravel()
    if w.size != G.size:
        raise ModelError(f"FRF fit: {w.size} frequencies but {G.size} response values")
    if w.size < 4:
        raise ModelError(f"FRF fit: need at least 4 frequencies, got {w.size}")
    if not (np.all(np.isfinite(w)) and np.all(np.isfinite(G))):
        raise ModelError("FRF fit: non-finite frequency or response value")
    if np.any(w <= 0):
        raise ModelError("FRF fit: frequencies must be positive (rad/s)")
    if np.any(np.abs(G) == 0):
        raise ModelError("FRF fit: zero response values cannot be fitted in relative terms")
    order = np.argsort(w)
    w, G = w[order], G[order]
    if np.any(np.diff(w) == 0):
        raise ModelError("FRF fit: repeated frequencies")
    mag = np.abs(G)
    if not np.isfinite(mag.max()) or mag.min() < 1e-100 * mag.max():
        raise ModelError(f"FRF fit: the response magnitudes span {mag.min():.3g} to {mag.max():.3g}, more "
                         "than 100 decades (or overflow): a relative fit cannot weigh such data (a value "
                         "that should be zero, or wrong units on part of the data?)")
    if w[-1] > 1e100 * w[0]:
        raise ModelError(f"FRF fit: the frequencies span {w[0]:.3g} to {w[-1]:.3g} rad/s, more than 100 "
                         "decades")
    return w, G


def _basis(s, poles):
    """Real basis: one column per real pole, two per complex pair (upper pole given)."""
    cols = []
    for p in poles:
        if p.imag == 0:
            cols.append(1.0 / (s - p.real))
        else:
            a, b = 1.0 / (s - p), 1.0 / (s - np.conj(p))
            cols += [a + b, 1j * a - 1j * b]
    return np.column_stack(cols)


def _realisation(poles, x):
    """(A, B, C) with C (sI - A)^-1 B = sum of the basis columns times x.

    A pair p = a + jb with coefficients (x1, x2), i.e. residue x1 + j x2, is the
    block A = [[a, b], [-b, a]], B = [2, 0]^T, C = [x1, x2]."""
    n = sum(1 if p.imag == 0 else 2 for p in poles)
    A, B, C = np.zeros((n, n)), np.zeros((n, 1)), np.zeros((1, n))
    k = 0
    for p in poles:
        if p.imag == 0:
            A[k, k], B[k, 0], C[0, k] = p.real, 1.0, x[k]
            k += 1
        else:
            A[k:k + 2, k:k + 2] = [[p.real, p.imag], [-p.imag, p.real]]
            B[k, 0] = 2.0
            C[0, k:k + 2] = x[k:k + 2]
            k += 2
    return A, B, C


def _eval(poles, x, omega):
    return _basis(1j * omega, poles) @ x


def _split_poles(lam, tol=1e-9):
    """Keep real poles and the upper member of each conjugate pair; reflect unstable ones."""
    lam = np.where(lam.real > 0, -lam.real + 1j * lam.imag, lam)
    out = []
    for p in lam:
        if abs(p.imag) <= tol * max(1.0, abs(p)):
            out.append(complex(p.real, 0.0))
        elif p.imag > 0:
            out.append(p)
    # a real pole at the origin would make the model unbounded: nudge it
    return np.array([complex(min(p.real, -1e-9 * max(1.0, abs(p))), p.imag) for p in out])


def _lstsq(M, rhs, wgt):
    Mw = M * wgt[:, None]
    rw = rhs * wgt
    Ar = np.vstack([Mw.real, Mw.imag])
    br = np.concatenate([rw.real, rw.imag])
    scale = np.linalg.norm(Ar, axis=0)
    scale[scale == 0] = 1.0
    sol, *_ = np.linalg.lstsq(Ar / scale, br, rcond=None)
    return sol / scale


def _relocate(z, F, poles, wgt, admissible, const: bool = False):
    r"""One vector-fitting step [GS]_: the new poles from the current ones.

    With :math:`\sigma(z) = 1 + \sum_i \tilde r_i\phi_i(z)` (the real basis
    :func:`_basis` of ``poles``), :math:`\sigma F \approx [c_0 +] \sum_i r_i\phi_i`
    is solved by weighted linear least squares; the zeros of :math:`\sigma`
    (eigenvalues of :math:`A - BC` for its realisation) passed through
    ``admissible`` are the new poles.  ``z`` is :math:`j\omega` for a frequency
    response (:func:`fit_frf`) or a real variable such as :math:`\omega^2`
    (:func:`fit_magnitude`, with the constant ``c_0``).
    """
    Phi = _basis(z, poles)
    m = Phi.shape[1]
    cols = [Phi, -F[:, None] * Phi]
    if const:
        cols.insert(0, np.ones((np.size(z), 1)))
    sol = _lstsq(np.hstack(cols), F.astype(complex), wgt)
    A, B, C = _realisation(poles, sol[-m:])
    return admissible(np.linalg.eigvals(A - B @ C))


def _check_int(v, name, lo):
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)) or v < lo:
        raise ModelError(f"FRF fit: {name} must be an integer >= {lo}, got {v!r}")


def _vf(w, G, order, iterations, tol):
    """Vector fitting on data normalised to frequencies and magnitudes of order one
    (the fit is equivariant: poles scale with the frequency unit, the coefficients
    with the frequency and response units); returns (poles, coefficients, RMS
    relative residual) in the units of the data."""
    w0 = float(np.sqrt(w.min() * w.max()))
    g0 = float(np.abs(G).max())
    poles, x, res = _vf_unit(w / w0, G / g0, order, iterations, tol)
    return poles * w0, x * (g0 * w0), res


def _vf_unit(w, G, order, iterations, tol):
    s = 1j * w
    npairs, nreal = order // 2, order % 2
    beta = np.logspace(np.log10(w.min()), np.log10(w.max()), max(npairs, 1))[:npairs]
    poles = [complex(-0.01 * b, b) for b in beta]
    if nreal:
        poles.append(complex(-np.sqrt(w.min() * w.max()), 0.0))
    poles = np.array(poles)
    wgt = 1.0 / np.abs(G)
    for _ in range(iterations):
        new = _relocate(s, G, poles, wgt, _split_poles)
        if new.size != poles.size:   # a pair became two real poles or vice versa: accept as is
            poles = new
            continue
        moved = np.max(np.abs(np.sort_complex(new) - np.sort_complex(poles)) / np.maximum(np.abs(poles), 1e-12))
        poles = new
        if moved < tol:
            break
    Phi = _basis(s, poles)
    x = _lstsq(Phi, G, wgt)
    H = Phi @ x
    res = float(np.sqrt(np.mean(np.abs(H - G) ** 2 / np.abs(G) ** 2)))
    return poles, x, res


#: a held-out check is made when there are fewer than this many frequencies per state
_HELD_OUT_RATIO = 4
#: the fit is flagged when the held-out residual exceeds both this and 3 x the in-sample one
_HELD_OUT_TOL = 0.01


def fit_frf(omega, response, order: int, *, iterations: int = 30, tol: float = 1e-8) -> RationalFit:
    r"""Fit a stable, strictly proper rational model of ``order`` states to FRF data.

    Parameters
    ----------
    omega : array_like
        Frequencies [rad/s], positive.
    response : array_like
        Complex response at ``omega`` (e.g. m/N).
    order : int
        Number of poles (an even number gives conjugate pairs only).  At most
        the number of frequencies: each state brings two real unknowns (pole
        and residue), each frequency two real data.
    iterations : int
        Largest number of pole relocations.
    tol : float
        Stop when the poles move by less than this (relative).

    Returns
    -------
    RationalFit
        With fewer than 4 frequencies per state the fit is repeated without
        every fourth frequency and its residual on those held-out points is
        stored in ``held_out_residual``; a fit that only reproduces the points
        it was fitted to (held-out residual above 1 % and 3 x the in-sample
        residual) gets a note saying it is over-fitted.

    Raises
    ------
    ModelError
        Malformed data, an order that is not a positive integer or larger
        than the number of frequencies (the data cannot determine the model).

    Examples
    --------
    >>> import numpy as np
    >>> from mutext.frfit import fit_frf
    >>> w = np.linspace(0.1, 30.0, 300)                 # rad/s
    >>> fit = fit_frf(w, 1.0 / (100.0 - w ** 2 + 0.2j * w), 2)
    >>> np.round(np.sort_complex(fit.poles), 4), bool(fit.residual < 1e-10)
    (array([-0.1+9.9995j]), True)
    """
    w, G = _check_data(omega, response)
    if not (isinstance(order, (int, np.integer)) and not isinstance(order, (bool, np.bool_)) and order >= 1):
        raise ModelError(f"FRF fit: order must be a positive integer, got {order!r}")
    _check_int(iterations, "iterations", 0)
    if not (isinstance(tol, (int, float, np.integer, np.floating)) and np.isfinite(tol) and tol > 0):
        raise ModelError(f"FRF fit: tol must be a positive finite number, got {tol!r}")
    if order > w.size:
        raise ModelError(f"FRF fit: order {order} is larger than the number of frequencies ({w.size}): "
                         f"{2 * order} real unknowns from {2 * w.size} real data, the model is not "
                         f"determined by the data (use order <= {w.size}, or much less to average noise)")
    poles, x, res = _vf(w, G, int(order), iterations, tol)
    notes = []
    held = None
    if _HELD_OUT_RATIO * order > w.size:
        test = np.zeros(w.size, bool)
        test[2:-1:4] = True          # every fourth point, never the end points
        train = ~test
        if test.any() and order <= train.sum():
            pt, xt, _ = _vf(w[train], G[train], int(order), iterations, tol)
            Ht = _eval(pt, xt, w[test])
            held = float(np.sqrt(np.mean(np.abs(Ht - G[test]) ** 2 / np.abs(G[test]) ** 2)))
        else:
            held = float("inf")
        if not held <= max(_HELD_OUT_TOL, 3.0 * res):
            notes.append(f"over-fitted: order {order} on {w.size} frequencies reproduces the data "
                         f"(residual {res:.3g}) but refitted without every fourth frequency it misses those "
                         f"by {held:.3g} (RMS relative); the model is not reliable between the data points "
                         f"-- lower the order or measure more frequencies")
    A, B, C = _realisation(poles, x)
    sys = ss(A, B, C, np.zeros((1, 1)))
    fit = RationalFit(sys, A.shape[0], res, w, poles, notes, x)
    fit.held_out_residual = held
    return fit


def fit_frf_auto(omega, response, *, max_order: int = 24, tol: float = 0.02, min_order: int = 2) -> RationalFit:
    """The lowest even order (from ``min_order``) whose :func:`fit_frf` residual is at most ``tol``.

    If none reaches it up to ``max_order``, the best fit is returned with a note
    (noisy data: ``tol`` below the noise level cannot be reached).  Orders
    above the number of frequencies are not tried (with a note).

    Parameters
    ----------
    omega : (N,) array_like
        Frequencies in rad/s.
    response : (N,) complex array_like
        The measured response at ``omega``.
    max_order : int, optional
        Highest order tried.
    tol : float, optional
        Target RMS relative residual.
    min_order : int, optional
        Lowest order tried (rounded up to an even number, at least 2).

    Raises
    ------
    ModelError
        Malformed data; ``max_order`` or ``min_order`` not an integer, or no
        even order >= 2 between them; ``tol`` not a positive finite number.
    """
    _check_int(max_order, "max_order", 1)
    _check_int(min_order, "min_order", 0)
    if not (isinstance(tol, (int, float, np.integer, np.floating)) and np.isfinite(tol) and tol > 0):
        raise ModelError(f"FRF fit: tol must be a positive finite number, got {tol!r}")
    first = max(2, min_order + min_order % 2)
    if max_order < first:
        raise ModelError(f"FRF fit: max_order={max_order} leaves no even order to try "
                         f"(orders start at {first}; min_order={min_order})")
    w, G = _check_data(omega, response)
    top = min(max_order, w.size)
    if top < first:
        raise ModelError(f"FRF fit: {w.size} frequencies cannot determine a model of order {first} or more")
    best = None
    for n in range(first, top + 1, 2):
        f = fit_frf(w, G, n)
        if best is None or (f.residual < best.residual * 0.98 and not f.notes):
            best = f
        if f.residual <= tol and not any(m.startswith("over-fitted") for m in f.notes):
            return f
    best.notes.append(f"no order up to {top} reached the residual {tol:.3g}; "
                      f"best {best.residual:.3g} at order {best.order}"
                      + (f" (max_order {max_order} capped at the {w.size} frequencies)" if top < max_order else ""))
    return best


# --- measured resonances ------------------------------------------------------

_MAX_DAMPING = 0.3     # heavier pairs shape the background; they show no peak worth the name
_SIGNIFICANCE = 5.0    # a mode must move the response by this many noise standard deviations
_TOL_FACTOR = 1.3      # order search: a residual within 30 % of the noise level is "at the noise"
_SIGMA_MIN = 1e-6      # relative; no measurement is better (exact data fit to ~1e-10)
_MATCH_RADIUS = 3.0    # bootstrap pole matching radius, in units of |Re p| (half-power half-width)
_D4 = np.array([1.0, -4.0, 6.0, -4.0, 1.0])   # fourth difference


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


def _check_hz(freq_hz, response, who):
    """:func:`_check_data` for frequencies in Hz; returns (omega, G) sorted by frequency."""
    try:
        return _check_data(2.0 * np.pi * np.asarray(freq_hz, dtype=float), response)
    except ModelError as exc:
        raise ModelError(str(exc).replace("FRF fit", who).replace("(rad/s)", "(Hz)")) from None


def noise_level(freq_hz, response) -> float:
    r"""Relative noise level of a measured FRF, estimated from the data alone.

    With circular complex Gaussian noise of standard deviation :math:`\sigma`
    relative to :math:`|G|` (as :class:`mutext.rig.Noise`),
    :math:`G_k = G^0_k(1 + \sigma e_k)` and, to first order,
    :math:`L_k = \ln G_k = \ln G^0_k + \sigma e_k`.  The fourth difference
    along the frequency index,

    .. math::
        d_k = L_k - 4L_{k+1} + 6L_{k+2} - 4L_{k+3} + L_{k+4},
        \qquad L = \ln|G| + j\,\arg G \ \text{(phase unwrapped)},

    cancels any cubic trend of :math:`L` (mass and stiffness lines, the flanks
    of the resonances) and leaves, for white noise, circular Gaussian samples
    with :math:`E|d_k|^2 = (1+16+36+16+1)\sigma^2 = 70\sigma^2`, so
    :math:`|d_k|` is Rayleigh distributed with median
    :math:`\sqrt{35}\,\sqrt{2\ln 2}\,\sigma`.  The estimate is

    .. math::
        \hat\sigma = \frac{\operatorname{median}_k |d_k|}{\sqrt{35}\,\sqrt{2\ln 2}}

    (the median absolute deviation about zero, the noise having zero mean),
    taken over the samples away from sharp features: a first estimate from all
    samples flags those with :math:`|d_k|` above 4 times its Rayleigh scale
    (3e-4 probability for noise alone), and each run of flagged samples is
    excluded together with as many samples again plus 2 on each side, where a
    resonance or antiresonance still curves :math:`L` faster than a cubic but
    no longer stands out (fewer than 10 samples left: the first estimate).

    Why not simply a median of second differences (variance :math:`6\sigma^2`):
    near a resonance they keep the curvature of :math:`\ln G` over about
    :math:`1/\sqrt\sigma` frequency steps on each side, and on 0.5 Hz grids
    with 1-2 % damping that biased the median 15-30 % high; the fourth
    difference with the exclusion stays within a few percent (scatter 5-10 %
    with 200-500 frequencies).

    Parameters
    ----------
    freq_hz : array_like
        Frequencies [Hz], positive; uniformly or smoothly (e.g. logarithmically)
        spaced, at least 8.
    response : array_like
        Complex response at ``freq_hz``.

    Returns
    -------
    float
        :math:`\hat\sigma`, e.g. 0.01 for 1 % noise.  Noise independent from
        one frequency to the next is assumed; with an absolute noise floor the
        value is a typical (median) relative level.

    Raises
    ------
    mutext.errors.ModelError
        Malformed data (see :func:`fit_frf`) or fewer than 8 frequencies.
    """
    w, G = _check_hz(freq_hz, response, "noise level")
    if w.size < 8:
        raise ModelError(f"noise level: need at least 8 frequencies, got {w.size}")
    L = np.log(np.abs(G)) + 1j * np.unwrap(np.angle(G))
    a = np.abs(np.convolve(L, _D4, mode="valid"))
    rayleigh = np.sqrt(2 * np.log(2))                  # median of a Rayleigh variable of unit scale
    scale = np.median(a) / rayleigh
    flagged = a > 4.0 * scale
    excluded = flagged.copy()
    edges = np.flatnonzero(np.diff(np.r_[0, flagged.astype(int), 0]))
    for i, j in zip(edges[::2], edges[1::2]):          # runs flagged[i:j]
        g = (j - i) + 2
        excluded[max(0, i - g):j + g] = True
    if np.count_nonzero(~excluded) >= 10:
        scale = np.median(a[~excluded]) / rayleigh
    return float(scale / np.sqrt(0.5 * np.sum(_D4 ** 2)))


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
    lo, hi = w[0] / (2 * np.pi), w[-1] / (2 * np.pi)
    if band is not None:
        try:
            b0, b1 = (float(v) for v in band)
        except (TypeError, ValueError):
            raise ModelError(f"resonances: band must be (fmin, fmax) in Hz, got {band!r}") from None
        if not (np.isfinite(b0) and np.isfinite(b1) and b0 < b1):
            raise ModelError(f"resonances: band must be finite with fmin < fmax, got {band!r}")
        lo, hi = max(lo, b0), min(hi, b1)
    if noise is None:
        sigma = noise_level(w / (2 * np.pi), G)
    else:
        try:
            sigma = float(noise)
        except (TypeError, ValueError):
            raise ModelError(f"resonances: noise must be a number, got {noise!r}") from None
        if not (np.isfinite(sigma) and sigma >= 0):
            raise ModelError(f"resonances: noise must be finite and >= 0, got {noise!r}")
    for name, v, least in (("max_order", max_order, 2), ("n_boot", n_boot, 0)):
        if not (isinstance(v, (int, np.integer)) and v >= least):
            raise ModelError(f"resonances: {name} must be an integer >= {least}, got {v!r}")
    try:
        gen = np.random.default_rng(rng)
    except (TypeError, ValueError):
        raise ModelError(f"resonances: rng must be a seed or numpy.random.Generator, got {rng!r}") from None
    with blas_single_thread():      # some 20 small least-squares fits: extra threads only spin
        return _resonances(w, G, lo, hi, sigma, order, max_order, n_boot, gen)


def _resonances(w, G, lo, hi, sigma, order, max_order, n_boot, gen):
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

    f_std = np.full(P.size, 0.0 if sigma == 0 else np.nan)
    z_std = f_std.copy()
    if P.size and sigma > 0 and n_boot >= 2:
        amp = sigma * np.abs(H) / np.sqrt(2)
        boot = np.empty((n_boot, P.size), dtype=complex)
        for b in range(n_boot):
            e = gen.standard_normal((2, w.size))
            refit = fit_frf(w, H + amp * (e[0] + 1j * e[1]), fit.order)
            boot[b] = _match(P, refit.poles[refit.poles.imag > 0])
        for i in range(P.size):
            q = boot[~np.isnan(boot[:, i]), i]
            if q.size >= max(2, n_boot / 2):      # else the pole is not reproducible at this noise
                f_std[i] = np.std(np.abs(q) / (2 * np.pi), ddof=1)
                z_std[i] = np.std(-q.real / np.abs(q), ddof=1)

    out = [Resonance(float(abs(p) / (2 * np.pi)), float(-p.real / abs(p)),
                     float(abs(fit.response([abs(p)])[0])), float(fs), float(zs), complex(p))
           for p, fs, zs in zip(P, f_std, z_std)]
    return sorted(out, key=lambda r: r.freq_hz)


# ----------------------------------------------------------------------------
# magnitude-only fits with a stable, minimum-phase result (D scalings)
# ----------------------------------------------------------------------------

@dataclass
class MagnitudeFit:
    """A fitted magnitude :math:`|\\hat D(j\\omega)|`: SISO, stable, minimum phase, biproper
    (:func:`fit_magnitude`; the D scalings of :mod:`mutext.dk`).

    Attributes
    ----------
    sys : control.StateSpace
        Realisation of :math:`\\hat D(s)`.
    order : int
        Number of poles (can be below the order asked of :func:`fit_magnitude`
        when roots at the edges of the data cancel).
    error : float
        Largest weighted error of :math:`\\log|\\hat D(j\\omega)|` against the data.
    zeros, poles : ndarray
        All in the open left half plane.
    gain : float
        :math:`\\hat D(\\infty)`.
    """
    sys: ct.StateSpace
    order: int
    error: float
    zeros: np.ndarray
    poles: np.ndarray
    gain: float

    def __call__(self, omega) -> np.ndarray:
        """:math:`\\hat D(j\\omega)` at the frequencies ``omega`` (rad/s)."""
        s = 1j * np.asarray(omega, dtype=float)
        out = np.full(s.shape, self.gain, dtype=complex)
        for z in self.zeros:
            out = out * (s - z)
        for p in self.poles:
            out = out / (s - p)
        return out

    def inverse(self) -> ct.StateSpace:
        """Realisation of :math:`\\hat D(s)^{-1}` (stable: the zeros of :math:`\\hat D` are)."""
        return _zpk_ss(self.poles, self.zeros, 1.0 / self.gain)


def _constant(g: float) -> ct.StateSpace:
    return ss(np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), [[g]])


def _sections(roots):
    """Split roots into real monic first- and second-order polynomials."""
    roots = list(np.asarray(roots, complex))
    lin, quad = [], []
    while roots:
        a = roots.pop(0)
        if abs(a.imag) > 1e-12 * max(1.0, abs(a)):
            if not roots:
                raise ModelError("magnitude fit: a complex root has no conjugate partner")
            k = int(np.argmin([abs(b - a.conjugate()) for b in roots]))
            b = roots.pop(k)
            quad.append(np.real(np.poly([a, b])))
        else:
            lin.append(np.array([1.0, -a.real]))
    return lin, quad


def _zpk_ss(zeros, poles, gain) -> ct.StateSpace:
    """Real realisation of ``gain * prod(s - z) / prod(s - p)`` (biproper) as a cascade
    of first- and second-order sections, which stays well conditioned when the
    roots spread over decades."""
    if len(zeros) != len(poles):
        raise ModelError("magnitude fit: numerator and denominator degrees differ")
    lz, qz = _sections(zeros)
    lp, qp = _sections(poles)
    pairs = []
    try:
        for den in qp:
            pairs.append((qz.pop(0) if qz else np.polymul(lz.pop(0), lz.pop(0)), den))
        for num in qz:
            pairs.append((num, np.polymul(lp.pop(0), lp.pop(0))))
        pairs += list(zip(lz, lp))
    except IndexError:
        raise ModelError("magnitude fit: cannot pair the zeros and poles") from None
    sys = _constant(gain)
    for num, den in pairs:
        sys = ct.series(sys, ct.ss(ct.tf(num, den)))
    return ss(sys.A, sys.B, sys.C, sys.D)


def _log_fit_error(fit: MagnitudeFit, omega, mag, weight):
    return float(np.max(weight * np.abs(np.log(np.abs(fit(omega))) - np.log(mag))))


def _admissible(lam, xmin, xmax, zeta_min: float = 0.1):
    """Relocated poles of Phi(x) made admissible: one entry per real pole or conjugate
    pair (Im > 0), off the positive real axis (that would be a pole of D on the
    imaginary axis; damping ratio at least ``zeta_min``) and within two decades of
    the data in magnitude."""
    out = []
    th_min = 2.0 * np.arcsin(zeta_min)       # arg of x for damping ratio zeta: 2 asin(zeta)
    for v in lam:
        if v.imag < -1e-12 * abs(v):
            continue                           # the partner of a pair already taken
        r = float(np.clip(abs(v), xmin * 1e-2, xmax * 1e2))
        th = float(np.angle(v)) if abs(v.imag) > 1e-12 * abs(v) else (np.pi if v.real <= 0 else 0.0)
        if th < th_min:
            th = np.pi if abs(v.imag) <= 1e-12 * abs(v) else th_min
        out.append(complex(-r) if th >= np.pi - 1e-12 else r * np.exp(1j * th))
    # separate coincident real poles (keeps the basis independent)
    real = sorted(-a.real for a in out if a.imag == 0)
    for i in range(1, len(real)):
        real[i] = max(real[i], real[i - 1] * 1.01)
    return [complex(-v) for v in real] + [a for a in out if a.imag != 0]


def _stable_sqrt(v) -> complex:
    """The root of ``s^2 = -v`` in the closed left half plane."""
    r = np.sqrt(-complex(v))
    return complex(-abs(r.real), r.imag)


def fit_magnitude(omega, mag, order: int, weight=None, iterations: int = 8) -> MagnitudeFit:
    r"""Fit :math:`|\hat D(j\omega)| \approx` ``mag`` by a stable, minimum-phase, biproper :math:`\hat D`.

    Parameters
    ----------
    omega : array_like
        Positive frequencies (rad/s).
    mag : array_like
        Positive magnitudes.
    order : int
        0 (a constant) to 5.
    weight : array_like, optional
        Positive weight of each frequency on the error of :math:`\log|\hat D|`
        (default 1).
    iterations : int
        Largest number of vector-fitting pole relocations.

    Returns
    -------
    MagnitudeFit
        Its poles and zeros lie within the band of ``omega`` in magnitude: a
        root beyond the band acts there as a constant (or as ``s``) and is moved
        to the band's edge with the gain compensated; a zero and a pole that
        meet at an edge cancel, so the fit's order can be below ``order``.

    Raises
    ------
    ModelError
        Empty or mismatched data, non-positive frequencies or magnitudes,
        order outside 0-5.
    SolverError
        The constrained fit failed or gave no valid spectral factor.

    Notes
    -----
    With :math:`x = (\omega/\omega_0)^2` the target :math:`\Phi_k = \text{mag}_k^2`
    is approximated by :math:`\Phi(x) = c_0 + \sum_i c_i/(x - a_i)`; the poles
    :math:`a_i` (negative real, or complex pairs with damping ratio of the
    resulting :math:`\hat D` poles at least 0.1) come from vector fitting with
    relative weighting, the residues from a convex least-squares problem with
    :math:`\Phi \ge 0` on a dense grid.  As :math:`x = -s^2`, every pole and
    zero :math:`\xi` of :math:`\Phi` gives the root of :math:`\hat D` that is the
    left-half-plane solution of :math:`s^2 = -\xi\,\omega_0^2`, and
    :math:`\hat D(\infty) = \sqrt{c_0}`.

    Examples
    --------
    >>> import numpy as np
    >>> w = np.logspace(-2, 3, 60)
    >>> fit = fit_magnitude(w, np.abs((1j * w + 1) / (1j * w + 10)), 1)
    >>> np.round(fit.zeros.real, 6), np.round(fit.poles.real, 6), round(fit.gain, 6)
    (array([-1.]), array([-10.]), 1.0)
    """
    omega = np.asarray(omega, dtype=float).ravel()
    mag = np.asarray(mag, dtype=float).ravel()
    if omega.size != mag.size or omega.size == 0:
        raise ModelError(f"omega and mag must be non-empty and of equal length (got {omega.size} "
                         f"and {mag.size})")
    if not (np.all(np.isfinite(omega)) and np.all(omega > 0)):
        raise ModelError("magnitude fit: frequencies must be positive and finite")
    if not (np.all(np.isfinite(mag)) and np.all(mag > 0)):
        raise ModelError("magnitude fit: magnitudes must be positive and finite")
    if not (isinstance(order, (int, np.integer)) and 0 <= order <= 5):
        raise ModelError(f"magnitude fit: order must be an integer between 0 and 5, got {order!r}")
    if weight is None:
        weight = np.ones_like(omega)
    else:
        weight = np.asarray(weight, dtype=float).ravel()
        if weight.size != omega.size or not np.all(np.isfinite(weight)) or np.any(weight <= 0):
            raise ModelError("magnitude fit: weight must be positive, finite and one per frequency")
    order = int(order)
    if order == 0:
        # the weighted least-squares constant for log|D|
        g = float(np.exp(np.sum(weight ** 2 * np.log(mag)) / np.sum(weight ** 2)))
        fit = MagnitudeFit(_constant(g), 0, 0.0, np.zeros(0, complex), np.zeros(0, complex), g)
        fit.error = _log_fit_error(fit, omega, mag, weight)
        return fit
    w0 = float(np.exp(np.mean(np.log(omega))))
    x = (omega / w0) ** 2
    Phi = mag ** 2
    # relative error of Phi is about twice the error of log|D|
    rw = weight / Phi
    xmin, xmax = x.min(), x.max()
    poles = [complex(-v) for v in np.logspace(np.log10(xmin), np.log10(xmax), order + 2)[1:-1]]
    for _ in range(iterations):
        # the vector-fitting step of fit_frf on the real variable x, with a constant term
        new = _relocate(x, Phi, poles, rw, lambda lam: _admissible(lam, xmin, xmax), const=True)
        converged = len(new) == len(poles) and np.allclose(
            np.sort_complex(np.array(new)), np.sort_complex(np.array(poles)), rtol=1e-6)
        poles = new
        if converged:
            break
    B = _basis(x, poles).real
    A = np.hstack([np.ones((x.size, 1)), B]) * rw[:, None]
    # column scaling: the basis functions differ by decades in size
    cs = 1.0 / np.max(np.abs(A), axis=0)
    coef, *_ = np.linalg.lstsq(A * cs, Phi * rw, rcond=None)
    coef = coef * cs
    xd = np.concatenate([[0.0], np.logspace(np.log10(xmin) - 3, np.log10(xmax) + 3, 400)])
    Bd = np.hstack([np.ones((xd.size, 1)), _basis(xd, poles).real])
    floor = 1e-3 * Phi.min()
    if coef[0] <= floor or np.any(Bd @ coef < floor):
        import cvxpy as cp
        c = cp.Variable(order + 1)
        prob = cp.Problem(cp.Minimize(cp.sum_squares((A * cs) @ c - Phi * rw)),
                          [(Bd * cs) @ c >= floor, c[0] * cs[0] >= floor])
        try:
            prob.solve(solver="CLARABEL")
        except cp.SolverError as exc:
            raise SolverError(f"magnitude fit of order {order}: the convex fit failed ({exc})") from None
        if c.value is None:
            raise SolverError(f"magnitude fit of order {order}: the convex fit failed (status {prob.status})")
        coef = np.asarray(c.value, float) * cs
    c0, ci = max(coef[0], floor), coef[1:]
    # zeros of Phi(x) = c0 (1 + (ci / c0)^T (xI - Ap)^-1 bp): eigenvalues of Ap - bp ci^T / c0
    Ap, bp, _ = _realisation(poles, np.zeros(sum(1 if a.imag == 0 else 2 for a in poles)))
    bp = bp[:, 0]
    xi = np.linalg.eigvals(Ap - np.outer(bp, ci) / c0)
    if np.any((np.abs(xi.imag) <= 1e-9 * np.abs(xi)) & (xi.real > 0)):
        # a simple root at x > 0 means Phi changes sign between the dense grid points
        raise SolverError(f"magnitude fit of order {order}: |D|^2 is not positive on the whole axis")
    # x = -s^2: each root of Phi gives the stable one of s = +/- sqrt(-root)
    zs = [_stable_sqrt(v) * w0 for v in xi]
    pz = []
    for a in poles:
        pz += [_stable_sqrt(a) * w0] if a.imag == 0 else [_stable_sqrt(a) * w0, _stable_sqrt(a.conjugate()) * w0]
    poles = np.array(pz, dtype=complex)
    zeros = np.array(zs)
    # conjugate pairs must be exact for a real realisation
    zeros = np.where(np.abs(zeros.imag) < 1e-9 * np.abs(zeros), zeros.real + 0j, zeros)
    if np.any(zeros.real >= -1e-9 * np.abs(zeros)):
        raise SolverError(f"magnitude fit of order {order}: a zero of the fit lies on the imaginary axis")
    gain = float(np.sqrt(c0))
    # Roots far outside the data only act as constants (above) or as s (below)
    # there, but they spread the eigenvalues of the scaled plant over many
    # decades, which the K step's LMIs do not tolerate: move them to the edge
    # of the data band, keeping the in-band magnitude (the gain absorbs |r|/edge).
    # A zero and a pole moved to the same edge cancel and are dropped.
    lo, hi = omega.min(), omega.max()

    def clip(roots, sign):
        nonlocal gain
        out = []
        for r in roots:
            if abs(r) > hi:
                gain *= (abs(r) / hi) ** sign
                out.append(-hi + 0j)
            elif abs(r) < lo:
                out.append(-lo + 0j)
            else:
                out.append(r)
        return out
    zl, pl = clip(zeros, 1), clip(poles, -1)
    for edge in (-hi + 0j, -lo + 0j):
        while edge in zl and edge in pl:
            zl.remove(edge)
            pl.remove(edge)
    zeros, poles = np.array(zl, dtype=complex), np.array(pl, dtype=complex)
    fit = MagnitudeFit(_zpk_ss(zeros, poles, gain), len(poles), 0.0, zeros, poles, gain)
    fit.error = _log_fit_error(fit, omega, mag, weight)
    return fit


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
    from scipy.optimize import least_squares, minimize
    from scipy.signal import find_peaks
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
    target = np.log(env)
    # the peaks that stand out from their surroundings by at least 20 %
    idx, props = find_peaks(target, prominence=np.log(1.2))
    keep = np.argsort(props["prominences"])[::-1][:int(max_sections)] if idx.size else []
    idx = np.sort(idx[keep]) if idx.size else idx
    s = 1j * omega
    base = float(np.exp(np.median(target)))

    def unpack(p):
        g, a, b = base * np.exp(p[0]), float(np.exp(p[1])), float(np.exp(p[2]))
        secs = [(float(np.exp(p[3 + 3 * k])), 1.0 + float(np.exp(p[4 + 3 * k])), float(np.exp(p[5 + 3 * k])))
                for k in range((len(p) - 3) // 3)]
        return g, (a, b), secs

    def logmag(p):
        g, (a, b), secs = unpack(p)
        out = np.log(g) + np.log(np.abs((s + a) / (s + b)))
        for w0, r, z in secs:
            out += np.log(np.abs((s * s + 2 * z * w0 * s + w0 * w0) / (s * s + 2 * (z / r) * w0 * s + w0 * w0)))
        return out

    def residuals(p):
        d = logmag(p) - target
        return np.where(d < 0.0, np.sqrt(3000.0) * d, d) / np.sqrt(d.size)

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

    def cost(p):
        return float(np.sum(residuals(np.clip(p, lower, upper)) ** 2))

    with np.errstate(all="ignore"):
        # the cost is smooth but not convex (the sections trade places): least squares from the
        # peaks, a simplex search from there, and least squares again
        p = least_squares(residuals, p0, method="trf", x_scale="jac", max_nfev=400 * p0.size,
                          bounds=(lower, upper)).x
        p = np.clip(minimize(cost, p, method="Nelder-Mead", options={"maxfev": 600 * p.size, "xatol": 1e-6,
                                                                     "fatol": 1e-12}).x, lower, upper)
        p = least_squares(residuals, p, method="trf", x_scale="jac", max_nfev=400 * p.size,
                          bounds=(lower, upper)).x
    if not np.isfinite(cost(p)):
        raise SolverError("envelope fit: the fit did not converge to finite values")
    g, (a, b), secs = unpack(p)
    # no frequency undershot: raise the gain by the largest shortfall (and a hair, for rounding)
    g *= float(np.exp(max(0.0, np.max(target - logmag(p))))) * (1.0 + 1e-7)
    zeros, poles = [complex(-a)], [complex(-b)]
    for w0, r, z in secs:
        zz, pp = _peaking(w0, r, z)
        zeros += list(zz)
        poles += list(pp)
    zeros, poles = np.array(zeros, dtype=complex), np.array(poles, dtype=complex)
    fit = MagnitudeFit(_zpk_ss(zeros, poles, g), len(poles), 0.0, zeros, poles, g)
    fit.error = float(np.max(np.log(np.abs(fit(omega))) - target))
    return fit
