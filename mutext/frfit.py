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

References
----------
.. [GS] B. Gustavsen and A. Semlyen, "Rational approximation of frequency domain
   responses by vector fitting", IEEE Trans. Power Delivery 14(3), 1999.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import control as ct
import numpy as np

from .errors import ModelError
from .lti import ss

__all__ = ["RationalFit", "fit_frf", "fit_frf_auto"]


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

    def response(self, omega) -> np.ndarray:
        """:math:`H(j\\omega)` of the fitted model."""
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


def fit_frf(omega, response, order: int, *, iterations: int = 30, tol: float = 1e-8) -> RationalFit:
    r"""Fit a stable, strictly proper rational model of ``order`` states to FRF data.

    Parameters
    ----------
    omega : array_like
        Frequencies [rad/s], positive.
    response : array_like
        Complex response at ``omega`` (e.g. m/N).
    order : int
        Number of poles (an even number gives conjugate pairs only).
    iterations : int
        Largest number of pole relocations.
    tol : float
        Stop when the poles move by less than this (relative).

    Returns
    -------
    RationalFit
    """
    w, G = _check_data(omega, response)
    if not (isinstance(order, (int, np.integer)) and order >= 1):
        raise ModelError(f"FRF fit: order must be a positive integer, got {order!r}")
    s = 1j * w
    npairs, nreal = order // 2, order % 2
    beta = np.logspace(np.log10(w.min()), np.log10(w.max()), max(npairs, 1))[:npairs]
    poles = [complex(-0.01 * b, b) for b in beta]
    if nreal:
        poles.append(complex(-np.sqrt(w.min() * w.max()), 0.0))
    poles = np.array(poles)
    wgt = 1.0 / np.abs(G)
    for _ in range(iterations):
        Phi = _basis(s, poles)
        m = Phi.shape[1]
        # sigma(s) G(s) = sum r_i phi_i  ->  [Phi, -G Phi] [x; xt] = G
        sol = _lstsq(np.hstack([Phi, -G[:, None] * Phi]), G, wgt)
        xt = sol[m:]
        A, B, C = _realisation(poles, xt)
        new = _split_poles(np.linalg.eigvals(A - B @ C))
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
    A, B, C = _realisation(poles, x)
    sys = ss(A, B, C, np.zeros((1, 1)))
    return RationalFit(sys, A.shape[0], res, w, poles, [], x)


def fit_frf_auto(omega, response, *, max_order: int = 24, tol: float = 0.02, min_order: int = 2) -> RationalFit:
    """The lowest even order (from ``min_order``) whose :func:`fit_frf` residual is at most ``tol``.

    If none reaches it up to ``max_order``, the best fit is returned with a note
    (noisy data: ``tol`` below the noise level cannot be reached).
    """
    best = None
    for n in range(max(2, min_order + min_order % 2), max_order + 1, 2):
        f = fit_frf(omega, response, n)
        if best is None or f.residual < best.residual * 0.98:
            best = f
        if f.residual <= tol:
            return f
    best.notes.append(f"no order up to {max_order} reached the residual {tol:.3g}; "
                      f"best {best.residual:.3g} at order {best.order}")
    return best
