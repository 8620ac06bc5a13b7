"""State space from a second-order mechanical model :math:`M\\ddot q + C\\dot q + Kq = Fu` with named ports
(:func:`mck_to_ss`)."""
from __future__ import annotations

from typing import Mapping, Sequence

import control as ct
import numpy as np

from ..errors import ModelError
from ._ss import ss


def _port_vector(spec, ndof: int, what: str) -> np.ndarray:
    if isinstance(spec, (int, np.integer)):
        if not 0 <= spec < ndof:
            raise ModelError(f"{what}: DOF index {spec} is outside 0..{ndof - 1}")
        v = np.zeros(ndof)
        v[spec] = 1.0
        return v
    v = np.asarray(spec, dtype=float).ravel()
    if v.shape != (ndof,):
        raise ModelError(f"{what}: a distribution vector must have {ndof} entries (one per DOF), got {v.size}")
    return v


_QUANTITIES = ("displacement", "velocity", "acceleration")


def mck_to_ss(M, C, K, inputs: Mapping[str, object], outputs: Mapping[str, object],
              *, dof_names: Sequence[str] | None = None) -> ct.StateSpace:
    r"""State-space model of :math:`M\ddot q + C\dot q + K q = F u` with named ports.

    The state is :math:`x = [q;\ \dot q]`, so

    .. math::
        A = \begin{bmatrix} 0 & I \\ -M^{-1}K & -M^{-1}C \end{bmatrix},\quad
        B = \begin{bmatrix} 0 \\ M^{-1}F \end{bmatrix}.

    Parameters
    ----------
    M, C, K : (ndof, ndof) array_like
        Mass (symmetric positive definite), damping and stiffness matrices in
        consistent units (SI: kg, N s/m, N/m).  ``C`` may be ``None`` (undamped).
    inputs : mapping name -> port
        Force inputs.  A port is a DOF index (unit force at that DOF) or a
        force-distribution vector of length ``ndof``.
    outputs : mapping name -> port
        Outputs.  A port is a DOF index (displacement), a vector (a linear
        combination of displacements), or a pair ``(quantity, dof_or_vector)``
        with quantity ``"displacement"``, ``"velocity"`` or ``"acceleration"``.
    dof_names : sequence of str, optional
        Names of the DOFs, used to name the states.

    Returns
    -------
    control.StateSpace
        With ``inputs``/``outputs`` names taken from the mappings.

    Examples
    --------
    >>> import numpy as np
    >>> from mutext.lti import mck_to_ss
    >>> G = mck_to_ss([[1.0]], [[0.2]], [[100.0]], inputs={"f": 0},
    ...               outputs={"x": 0, "v": ("velocity", 0)})     # 1 kg, 100 N/m: 10 rad/s
    >>> G.input_labels, G.output_labels, G.nstates
    (['f'], ['x', 'v'], 2)
    >>> np.round(G.poles(), 3)
    array([-0.1+9.999j, -0.1-9.999j])
    """
    M = np.atleast_2d(np.asarray(M, dtype=float))
    K = np.atleast_2d(np.asarray(K, dtype=float))
    ndof = M.shape[0]
    C = np.zeros((ndof, ndof)) if C is None else np.atleast_2d(np.asarray(C, dtype=float))
    for name, X in (("M", M), ("C", C), ("K", K)):
        if X.shape != (ndof, ndof):
            raise ModelError(f"{name} must be {ndof}x{ndof} (the size of M), got {X.shape[0]}x{X.shape[1]}")
        if not np.all(np.isfinite(X)):
            raise ModelError(f"{name} contains non-finite entries")
    if not np.allclose(M, M.T, rtol=1e-10, atol=0):
        raise ModelError("M is not symmetric")
    try:
        np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        raise ModelError("M is not positive definite (every DOF needs mass)") from None
    if not inputs:
        raise ModelError("at least one input port is needed")
    if not outputs:
        raise ModelError("at least one output port is needed")
    F = np.column_stack([_port_vector(p, ndof, f"input '{n}'") for n, p in inputs.items()])
    MinvK = np.linalg.solve(M, K)
    MinvC = np.linalg.solve(M, C)
    MinvF = np.linalg.solve(M, F)
    Z = np.zeros((ndof, ndof))
    A = np.block([[Z, np.eye(ndof)], [-MinvK, -MinvC]])
    B = np.vstack([np.zeros_like(MinvF), MinvF])
    rowsC, rowsD = [], []
    for n, p in outputs.items():
        if isinstance(p, tuple) and len(p) == 2 and isinstance(p[0], str):
            q, p = p
        else:
            q = "displacement"
        if q not in _QUANTITIES:
            raise ModelError(f"output '{n}': quantity must be one of {_QUANTITIES}, got '{q}'")
        v = _port_vector(p, ndof, f"output '{n}'")
        if q == "displacement":
            rowsC.append(np.concatenate([v, np.zeros(ndof)]))
            rowsD.append(np.zeros(F.shape[1]))
        elif q == "velocity":
            rowsC.append(np.concatenate([np.zeros(ndof), v]))
            rowsD.append(np.zeros(F.shape[1]))
        else:
            rowsC.append(v @ A[ndof:, :])
            rowsD.append(v @ MinvF)
    names = list(dof_names) if dof_names is not None else [f"q{i + 1}" for i in range(ndof)]
    states = names + [f"d{n}" for n in names]
    return ss(A, B, np.array(rowsC), np.array(rowsD), inputs=list(inputs), outputs=list(outputs),
              states=states)
