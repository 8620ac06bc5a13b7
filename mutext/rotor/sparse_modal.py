r"""The lowest modes of a rotor at speed by a sparse shift-invert eigen-solve (ARPACK).

:func:`mutext.rotor.analysis.modes` decomposes the whole first-order system
densely, :math:`O(n^3)` in the number of DOFs; a Campbell diagram or a fine
mesh needs only a few modes, which shift-invert Arnoldi iteration finds from
one sparse LU factorisation of the banded finite-element pencil
(:func:`sparse_modes`; ``benchmarks/bench_rotor.py`` times both).

References
----------
R. B. Lehoucq, D. C. Sorensen and C. Yang, *ARPACK Users' Guide*, SIAM, 1998
(implicitly restarted Arnoldi, shift-invert mode).
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..lti import blas_single_thread
from .analysis import Modes, _check_n, _finite_number, _speed, _values, whirl_index

__all__ = ["sparse_modes"]


def sparse_modes(model, speed: float | None = None, n: int = 6, *, values=None, shift_hz: float = 0.0,
                 extra: int = 8):
    r"""The ``n`` modes nearest ``shift_hz`` by shift-invert Arnoldi (ARPACK) on the sparse first-order pencil.

    The same problem as :func:`mutext.rotor.analysis.modes`, written as the pencil

    .. math::
        \begin{bmatrix} 0 & I\\ -K & -(C + \Omega G)\end{bmatrix} x
        = \lambda \begin{bmatrix} I & 0\\ 0 & M\end{bmatrix} x ,\qquad x = [q;\ \lambda q],

    solved by ``scipy.sparse.linalg.eigs`` with the shift :math:`\sigma = 2\pi j\,` ``shift_hz``
    (0: the slowest modes): one sparse LU factorisation of :math:`A - \sigma B` and a few
    dozen solves, instead of the dense :math:`O(n^3)` eigen-decomposition of the whole
    system.  The finite-element matrices are banded, so this pays off on fine meshes.
    ``2 n + extra`` eigenvalues are computed (each vibration is a conjugate pair); the
    overdamped roots are left out by the test of :mod:`mutext.rotor.analysis`.  A model
    with rigid-body modes makes :math:`A` singular: give a nonzero ``shift_hz`` then.

    Parameters
    ----------
    model : Structure or Rotor
        The assembled model, e.g. from :func:`mutext.rotor.load_model`.
    speed : float, optional
        Spin speed [rad/s]; default ``model.speed`` (0 for non-rotors).

    n : int, optional
        Number of modes.
    values : mapping or array_like, optional
        Parameter values: a mapping ``name -> value`` (SI) overriding nominal ones, or a full
        vector in the order of ``parameters`` (default: nominal, see :meth:`Structure.values`).

    shift_hz : float, optional
        Frequency [Hz] around which the modes are sought (0: the slowest).
    extra : int, optional
        Eigenvalues computed beyond ``2 n`` (margin for overdamped roots).

    Returns
    -------
    mutext.rotor.analysis.Modes
        Sorted by frequency, at most ``n`` modes.
    """
    import scipy.sparse as sp
    from scipy.sparse.linalg import ArpackNoConvergence, eigs

    n = _check_n(n)
    om = _speed(model, speed)
    shift = _finite_number(shift_hz, f"{model.name}: shift_hz", "Hz")
    v = _values(model, values)
    with blas_single_thread():
        M, C, K, G = model.matrices(v)
        N = M.shape[0]
        k = min(2 * n + int(extra), 2 * N - 2)
        Ms, Ks, Ds = (sp.csc_matrix(np.where(np.abs(X) > 0, X, 0.0)) for X in (M, K, C + om * G))
        A = sp.bmat([[None, sp.identity(N)], [-Ks, -Ds]], format="csc")
        B = sp.bmat([[sp.identity(N), None], [None, Ms]], format="csc")
        sigma = 2j * np.pi * shift if shift else 0.0
        try:
            lam, X = eigs(A, k=k, M=B, sigma=sigma, which="LM")
        except ArpackNoConvergence as exc:
            raise ModelError(f"{model.name}: the shift-invert eigen-solve did not converge "
                             f"({len(exc.eigenvalues)} of {k} eigenvalues); try another shift_hz") from None
        except RuntimeError as exc:          # singular A - sigma B (a rigid-body mode at the shift)
            raise ModelError(f"{model.name}: A - sigma B is singular at shift_hz = {shift:g} ({exc}); a model "
                             "with rigid-body modes needs a nonzero shift_hz") from None
    Q = X[:N]
    keep = lam.imag > 0
    lam, Q = lam[keep], Q[:, keep]
    Dsym = 0.5 * (C + om * G + (C + om * G).T)
    m = np.real(np.sum(np.conj(Q) * (M @ Q), axis=0))
    kk = np.real(np.sum(np.conj(Q) * ((0.5 * (K + K.T)) @ Q), axis=0))
    c = np.real(np.sum(np.conj(Q) * (Dsym @ Q), axis=0))
    under = (c <= 0.0) | (c < 2.0 * np.sqrt(np.maximum(kk, 0.0) * m))
    lam, Q = lam[under], Q[:, under]
    near = np.argsort(np.abs(lam.imag - 2 * np.pi * shift))[:n]          # the n nearest the shift ...
    order = near[np.argsort(lam[near].imag)]                              # ... by frequency
    lam, Q = lam[order], Q[:, order]
    for r in range(Q.shape[1]):
        j = int(np.argmax(np.abs(Q[:, r])))
        Q[:, r] /= Q[j, r]
    w = lam.imag
    whirl = np.array([whirl_index(Q[:, r], model.layout) for r in range(Q.shape[1])])
    return Modes(lam, w, w / (2 * np.pi), -lam.real / np.abs(lam), Q, whirl, om, model.dof_names)
