r"""The underdamped roots nearest a frequency by shift-invert Arnoldi on the sparse first-order pencil.

.. math::
    \begin{bmatrix} 0 & I\\ -K & -D\end{bmatrix} x
    = \lambda \begin{bmatrix} I & 0\\ 0 & M\end{bmatrix} x ,\qquad x = [q;\ \lambda q],

solved by ``scipy.sparse.linalg.eigs`` with the shift :math:`\sigma = 2\pi j f_s`: one
sparse LU factorisation of :math:`A - \sigma B` and a few dozen solves (systems of at most
:data:`SMALL` states by a dense eigen-solve instead).  Used by
:func:`mutext.rotor.sparse_modal.sparse_modes` and, for a few modes of a fine mesh, by
:func:`mutext.rotor.analysis.modes`.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError

#: Systems of at most this many states are solved densely: Arnoldi gains nothing there.
SMALL = 200


def state_matrix(M, K, D) -> np.ndarray:
    """The first-order system matrix :math:`[0, I; -M^{-1}K, -M^{-1}D]` of :math:`M\\ddot q + D\\dot q + Kq`."""
    N = M.shape[0]
    Minv = np.linalg.inv(M)
    return np.block([[np.zeros((N, N)), np.eye(N)], [-Minv @ K, -Minv @ D]])


def shift_invert_roots(M, K, D, n: int, shift_hz: float, extra: int, name: str):
    """``(lam, Q)``: at most ``n`` underdamped roots (Im > 0) nearest ``shift_hz``, by frequency, and their
    displacement shapes (columns, not normalised).

    ``2 n + extra`` eigenvalues are computed (each vibration is a conjugate pair); overdamped roots are
    recognised by their shape's damping, as in :mod:`mutext.rotor.analysis`.  Raises
    :class:`~mutext.errors.ModelError` when ARPACK does not converge or :math:`A - \\sigma B` is singular
    (a rigid-body mode at the shift)."""
    import scipy.sparse as sp
    from scipy.sparse.linalg import ArpackNoConvergence, eigs

    N = M.shape[0]
    k = min(2 * n + int(extra), 2 * N - 2)
    Ms, Ks, Ds = (sp.csc_matrix(np.where(np.abs(X) > 0, X, 0.0)) for X in (M, K, D))
    A = sp.bmat([[None, sp.identity(N)], [-Ks, -Ds]], format="csc")
    B = sp.bmat([[sp.identity(N), None], [None, Ms]], format="csc")
    sigma = 2j * np.pi * shift_hz if shift_hz else 0.0
    if 2 * N <= SMALL:
        # a small system: every root of M^-1 [K D] in first-order form by the balanced dense eigen-solve,
        # faster than Arnoldi there and never unconverged (as mutext.rotor.analysis does)
        lam, X = np.linalg.eig(state_matrix(M, K, D))
        if np.any(np.abs(lam - sigma) <= 1e-9 * np.max(np.abs(lam), initial=1.0)):
            raise ModelError(f"{name}: A - sigma B is singular at shift_hz = {shift_hz:g}; a model with "
                             "rigid-body modes needs a nonzero shift_hz")
        return _nearest(lam, X[:N], M, K, D, n, shift_hz)
    try:
        # a fixed start vector: the same modes to the last digit on every call (ARPACK's own start is random)
        v0 = np.random.default_rng(0).standard_normal(2 * N)
        lam, X = eigs(A, k=k, M=B, sigma=sigma, which="LM", v0=v0)
    except ArpackNoConvergence as exc:
        raise ModelError(f"{name}: the shift-invert eigen-solve did not converge "
                         f"({len(exc.eigenvalues)} of {k} eigenvalues); try another shift_hz") from None
    except RuntimeError as exc:          # singular A - sigma B (a rigid-body mode at the shift)
        raise ModelError(f"{name}: A - sigma B is singular at shift_hz = {shift_hz:g} ({exc}); a model "
                         "with rigid-body modes needs a nonzero shift_hz") from None
    return _nearest(lam, X[:N], M, K, D, n, shift_hz)


def _nearest(lam, Q, M, K, D, n, shift_hz):
    """The underdamped roots of ``lam`` (shapes ``Q``) nearest ``shift_hz``, at most ``n``, by frequency."""
    keep = lam.imag > 0
    lam, Q = lam[keep], Q[:, keep]
    Dsym = 0.5 * (D + D.T)
    m = np.real(np.sum(np.conj(Q) * (M @ Q), axis=0))
    kk = np.real(np.sum(np.conj(Q) * ((0.5 * (K + K.T)) @ Q), axis=0))
    c = np.real(np.sum(np.conj(Q) * (Dsym @ Q), axis=0))
    under = (c <= 0.0) | (c < 2.0 * np.sqrt(np.maximum(kk, 0.0) * m))
    lam, Q = lam[under], Q[:, under]
    near = np.argsort(np.abs(lam.imag - 2 * np.pi * shift_hz))[:n]          # the n nearest the shift ...
    order = near[np.argsort(lam[near].imag)]                                 # ... by frequency
    return lam[order], Q[:, order]
