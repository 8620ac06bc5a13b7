r"""Magnitude-only fits (the D scalings of :mod:`mutext.dk`): :math:`|D|^2` as a rational
function of :math:`\omega^2` by vector fitting, its residues kept positive, and a spectral
factorisation to a stable, minimum-phase, biproper :math:`\hat D(s)` (:class:`MagnitudeFit`)."""
from __future__ import annotations

from dataclasses import dataclass

import control as ct
import numpy as np

from .._solver import solve
from ..errors import ModelError, SolverError
from ..lti import ss
from ._vf import _basis, _realisation, _relocate


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
    omega, mag, weight, order = _magnitude_data(omega, mag, order, weight)
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
    poles = _phi_poles(x, Phi, rw, order, iterations)
    c0, ci = _phi_residues(x, Phi, rw, poles, order)
    zeros, poles, gain = _spectral_factor(poles, c0, ci, w0, order)
    zeros, poles, gain = _clip_to_band(zeros, poles, gain, omega.min(), omega.max())
    fit = MagnitudeFit(_zpk_ss(zeros, poles, gain), len(poles), 0.0, zeros, poles, gain)
    fit.error = _log_fit_error(fit, omega, mag, weight)
    return fit


def _magnitude_data(omega, mag, order, weight):
    """The data of :func:`fit_magnitude` checked: ``(omega, mag, weight, order)`` (weight 1 by default)."""
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
    return omega, mag, weight, int(order)


def _phi_poles(x, Phi, rw, order: int, iterations: int) -> list:
    """The poles of :math:`\\Phi(x)` by vector fitting with a constant term (relative weights ``rw``),
    started on the negative real axis across the data."""
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
    return poles


def _phi_residues(x, Phi, rw, poles, order: int):
    """``(c0, ci)`` of :math:`\\Phi(x) = c_0 + \\sum_i c_i\\phi_i(x)`: weighted least squares, or
    a convex fit with :math:`\\Phi` kept positive on a dense grid where that is not."""
    xmin, xmax = x.min(), x.max()
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
        solve(prob, f"magnitude fit of order {order}: the convex fit")
        if c.value is None:
            raise SolverError(f"magnitude fit of order {order}: the convex fit failed (status {prob.status})")
        coef = np.asarray(c.value, float) * cs
    return max(coef[0], floor), coef[1:]


def _spectral_factor(poles, c0, ci, w0: float, order: int):
    """``(zeros, poles, gain)`` of the stable, minimum-phase :math:`\\hat D(s)` with
    :math:`|\\hat D(j\\omega)|^2 = \\Phi((\\omega/\\omega_0)^2)`."""
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
    return zeros, poles, float(np.sqrt(c0))


def _clip_to_band(zeros, poles, gain: float, lo: float, hi: float):
    """Roots beyond the data band ``[lo, hi]`` moved to its edge: ``(zeros, poles, gain)``.

    Roots far outside the data only act as constants (above) or as s (below)
    there, but they spread the eigenvalues of the scaled plant over many
    decades, which the K step's LMIs do not tolerate: move them to the edge
    of the data band, keeping the in-band magnitude (the gain absorbs |r|/edge).
    A zero and a pole moved to the same edge cancel and are dropped."""
    zl, gain = _clip(zeros, 1, gain, lo, hi)
    pl, gain = _clip(poles, -1, gain, lo, hi)
    for edge in (-hi + 0j, -lo + 0j):
        while edge in zl and edge in pl:
            zl.remove(edge)
            pl.remove(edge)
    return np.array(zl, dtype=complex), np.array(pl, dtype=complex), gain


def _clip(roots, sign: int, gain: float, lo: float, hi: float):
    """``roots`` with those above ``hi`` (gain times ``(|r|/hi)**sign``) or below ``lo`` in
    magnitude moved to ``-hi`` or ``-lo``: ``(list of roots, gain)``."""
    out = []
    for r in roots:
        if abs(r) > hi:
            gain *= (abs(r) / hi) ** sign
            out.append(-hi + 0j)
        elif abs(r) < lo:
            out.append(-lo + 0j)
        else:
            out.append(r)
    return out, gain
