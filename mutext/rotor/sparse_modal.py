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

from ..lti import blas_single_thread
from ._shift_invert import shift_invert_roots
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
    n = _check_n(n)
    om = _speed(model, speed)
    shift = _finite_number(shift_hz, f"{model.name}: shift_hz", "Hz")
    v = _values(model, values)
    with blas_single_thread():
        M, C, K, G = model.matrices(v)
        lam, Q = shift_invert_roots(M, K, C + om * G, n, shift, extra, model.name)
    for r in range(Q.shape[1]):
        j = int(np.argmax(np.abs(Q[:, r])))
        Q[:, r] /= Q[j, r]
    w = lam.imag
    whirl = np.array([whirl_index(Q[:, r], model.layout) for r in range(Q.shape[1])])
    return Modes(lam, w, w / (2 * np.pi), -lam.real / np.abs(lam), Q, whirl, om, model.dof_names)
