r"""Linear time-invariant building blocks.

State-space models from second-order mechanical models, linear fractional
transformations (LFTs), the Redheffer star product, frequency responses and
the H-infinity norm.  Everything works on :class:`control.StateSpace`
(continuous time) and returns :class:`control.StateSpace`; python-control is
the container, the algorithms here are our own.

References
----------
.. [ZDG] K. Zhou, J. C. Doyle and K. Glover, *Robust and Optimal Control*,
   Prentice Hall, 1996 (LFTs: ch. 10; star product: sec. 10.3).
.. [BS] N. A. Bruinsma and M. Steinbuch, "A fast algorithm to compute the
   H-infinity norm of a transfer function matrix", *Systems & Control
   Letters* 14 (1990) 287-293.
.. [BBK] S. Boyd, V. Balakrishnan and P. Kabamba, "A bisection method for
   computing the H-infinity norm of a transfer matrix and related problems",
   *Math. Control Signals Systems* 2 (1989) 207-219.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Sequence

import control as ct
import numpy as np

from ._validation import Real, validate_params
from .errors import IllPosedError, ModelError

__all__ = [
    "ss", "as_ss", "check_finite", "mck_to_ss", "star", "lft_lower", "lft_upper",
    "lft_matrix", "freqresp", "sigma_max", "hinf_norm", "HinfNorm",
    "balance_states", "is_stable", "stability", "Stability", "closed_loop_poles", "is_real_number",
]


# ----------------------------------------------------------------------------
# construction and checks
# ----------------------------------------------------------------------------

def is_real_number(x) -> bool:
    """``x`` is a real number (int, float or their numpy kinds), not a bool, a string or an array.

    The check in front of every scalar option (tolerances, margins, weights): what it lets through is
    then tested for finiteness and range by the caller, which names the option in its error.

    Parameters
    ----------
    x : object
        The value to test.
    """
    return not isinstance(x, (bool, np.bool_)) and isinstance(x, (int, float, np.integer, np.floating))


def blas_single_thread():
    """Context manager limiting BLAS/LAPACK to one thread (threadpoolctl).

    The matrices of this package are small (up to a few hundred states): a
    multi-threaded BLAS gains nothing on them and, on a busy 2-core machine,
    loses 10-20x to threads spinning against each other.
    """
    from threadpoolctl import threadpool_limits
    return threadpool_limits(limits=1, user_api="blas")


def ss(A, B, C, D, *, inputs=None, outputs=None, states=None, name=None) -> ct.StateSpace:
    """Continuous-time state space with 2-D float matrices (empty blocks allowed).

    Raises :class:`ModelError` naming the matrix when an entry is not a number
    (a string, ``None``) or the sizes do not fit together: ``A`` is n x n,
    ``B`` n x m, ``C`` p x n, ``D`` p x m.

    Parameters
    ----------
    A : (n, n) array_like
        State matrix.
    B : (n, m) array_like
        Input matrix.
    C : (p, n) array_like
        Output matrix.
    D : (p, m) array_like
        Feedthrough matrix.
    inputs, outputs, states : sequence of str, optional
        Names of the m inputs, p outputs and n states (python-control's
        defaults ``u[i]``, ``y[i]``, ``x[i]`` when omitted).
    name : str, optional
        Name of the system, also used in the error messages.

    Examples
    --------
    >>> from mutext.lti import ss
    >>> G = ss([[-1.0]], [[1.0]], [[2.0]], [[0.0]], inputs=["u"], outputs=["y"])
    >>> G.nstates, G.ninputs, G.noutputs
    (1, 1, 1)
    >>> float(G(0j).real)                  # DC gain 2/1
    2.0
    """
    what = name or "system"
    _check_real(A, B, C, D, what=what)
    mats = []
    for label, X in zip("ABCD", (A, B, C, D)):
        try:
            arr = np.asarray(X) if not isinstance(X, np.ndarray) else X
        except (TypeError, ValueError):
            raise ModelError(f"{what}.{label} is not a matrix (rows of unequal length?): {X!r}"[:300]) from None
        if arr.size and (arr.dtype == object or arr.dtype.kind in "USV"):
            numbers = (int, float, np.integer, np.floating)
            odd = [v for v in np.ravel(arr) if not isinstance(v, numbers)][:1]
            bad = odd[0] if odd else None
            if odd:
                raise ModelError(f"{what}.{label} has an entry that is not a number ({bad!r}): every entry of "
                                 "A, B, C and D must be a real number")
        try:
            arr = np.real(arr) if np.iscomplexobj(arr) else arr
            mats.append(np.asarray(arr, dtype=float))
        except (TypeError, ValueError) as exc:
            raise ModelError(f"{what}.{label} is not a matrix of real numbers ({exc})") from None
    A, B, C, D = mats
    for label, X in zip("ABCD", mats):
        if X.ndim > 2:
            raise ModelError(f"{what}.{label} has {X.ndim} dimensions (shape {X.shape}); a state-space matrix "
                             "is 2-D")
    if A.ndim < 2 and A.size > 1:
        raise ModelError(f"{what}.A has shape {A.shape}; it must be a square n x n matrix (a 1-D array is "
                         "ambiguous)")
    A = np.atleast_2d(A) if A.size else np.zeros((0, 0))
    if A.shape[0] != A.shape[1]:
        raise ModelError(f"{what}.A has shape {A.shape}; it must be square (n x n)")
    n = A.shape[0]
    D = np.atleast_2d(D) if D.size or D.ndim == 2 else np.zeros((0, 0))
    if n:
        if B.ndim < 2:
            B = B.reshape(n, -1) if B.size % n == 0 and B.size else B
        if C.ndim < 2 and C.size:
            C = C.reshape(-1, n) if C.size % n == 0 else C
        if B.ndim != 2 or B.shape[0] != n:
            raise ModelError(f"{what}.B has shape {B.shape}; with A {n} x {n} it needs {n} rows")
        if C.ndim != 2 or C.shape[1] != n:
            raise ModelError(f"{what}.C has shape {C.shape}; with A {n} x {n} it needs {n} columns")
        if D.size == 0 and D.shape != (C.shape[0], B.shape[1]):
            D = np.zeros((C.shape[0], B.shape[1]))
        if D.shape != (C.shape[0], B.shape[1]):
            raise ModelError(f"{what}.D has shape {D.shape}; with B {B.shape} and C {C.shape} it must be "
                             f"{C.shape[0]} x {B.shape[1]}")
    else:
        B = np.zeros((0, D.shape[1]))
        C = np.zeros((D.shape[0], 0))
    kw = {}
    if inputs is not None:
        kw["inputs"] = list(inputs)
    if outputs is not None:
        kw["outputs"] = list(outputs)
    if states is not None:
        kw["states"] = list(states)
    if name is not None:
        kw["name"] = name
    return ct.ss(A, B, C, D, **kw)


def as_ss(sys, what: str = "system") -> ct.StateSpace:
    """Coerce a StateSpace, TransferFunction, (A, B, C, D) tuple or a constant
    matrix to a continuous-time :class:`control.StateSpace`.

    Parameters
    ----------
    sys : StateSpace, TransferFunction, tuple or array_like
        The system: a :class:`control.StateSpace` or :class:`control.TransferFunction`,
        an ``(A, B, C, D)`` tuple, or a constant (p, m) gain matrix (no states).
    what : str, optional
        Name of the system in the error messages.
    """
    if isinstance(sys, ct.StateSpace):
        _check_real(sys.A, sys.B, sys.C, sys.D, what=what)
        out = sys
    elif isinstance(sys, ct.TransferFunction):
        try:
            out = ct.ss(sys)
        except ValueError as exc:
            raise ModelError(f"{what}: this transfer function has no state-space form ({exc}); an improper "
                             "transfer function (numerator degree above the denominator's) has no finite "
                             "H-infinity norm or state-space realisation") from None
    elif isinstance(sys, (tuple, list)) and len(sys) == 4:
        _check_real(*sys, what=what)
        try:
            out = ss(*sys)
        except (TypeError, ValueError) as exc:
            raise ModelError(f"{what}: the (A, B, C, D) matrices are malformed or of inconsistent sizes "
                             f"({exc})") from None
    else:
        _check_real(sys, names="D", what=what)
        try:
            Dm = np.atleast_2d(np.asarray(sys, dtype=float))
        except (TypeError, ValueError):
            raise ModelError(f"{what}: expected a StateSpace, TransferFunction, (A, B, C, D) "
                             f"tuple or a constant matrix, got {type(sys).__name__}") from None
        out = ss(np.zeros((0, 0)), np.zeros((0, Dm.shape[1])), np.zeros((Dm.shape[0], 0)), Dm)
    if not ct.isctime(out, strict=False) or (out.dt not in (0, None)):
        raise ModelError(f"{what} must be continuous-time (dt=0); got dt={out.dt}")
    return out


def _check_real(*mats, names="ABCD", what="system"):
    """Raise :class:`ModelError` if a matrix has a nonzero imaginary part (it would
    be dropped with only a ComplexWarning when converted to float)."""
    for name, X in zip(names, mats):
        try:
            arr = np.asarray(X)
        except Exception:  # noqa: BLE001 - left to the conversion that follows
            continue
        if np.iscomplexobj(arr) and arr.size and np.any(np.imag(arr) != 0):
            raise ModelError(f"{what}.{name} is complex (nonzero imaginary parts): only real systems are "
                             f"supported (a complex matrix would lose its imaginary part)")


def check_finite(sys: ct.StateSpace, what: str = "system") -> None:
    """Raise :class:`ModelError` naming the first matrix with a NaN or infinite entry.

    Parameters
    ----------
    sys : control.StateSpace
        The system whose ``A``, ``B``, ``C``, ``D`` are checked.
    what : str, optional
        Name of the system in the error message.
    """
    for name in "ABCD":
        M = np.asarray(getattr(sys, name))
        if M.size and not np.all(np.isfinite(M)):
            i, j = np.argwhere(~np.isfinite(M))[0]
            raise ModelError(f"{what}.{name} contains a non-finite entry ({M[i, j]}) at row {i}, column {j}")


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


# ----------------------------------------------------------------------------
# interconnection
# ----------------------------------------------------------------------------

def star(P, Q, nu: int, ny: int) -> ct.StateSpace:
    r"""Redheffer star product :math:`P \star Q`.

    The last ``nu`` inputs of ``P`` (u) are driven by the first ``nu`` outputs
    of ``Q``; the last ``ny`` outputs of ``P`` (y) drive the first ``ny`` inputs
    of ``Q``.  The result maps ``[w_P; w_Q]`` to ``[z_P; z_Q]``::

        z_P <--|     |<-- w_P
               |  P  |
        y  ----|     |<-- u
         |                 ^
         +-->|     |-------+
             |  Q  |
        z_Q<-|     |<-- w_Q

    Raises :class:`IllPosedError` when the interconnection is not well posed
    (``I - P22(inf) Q11(inf)`` singular).

    Parameters
    ----------
    P : StateSpace or as accepted by :func:`as_ss`
        The upper system, inputs ``[w_P; u]`` and outputs ``[z_P; y]``.
    Q : StateSpace or as accepted by :func:`as_ss`
        The lower system, inputs ``[y; w_Q]`` and outputs ``[u; z_Q]``.
    nu : int
        Number of signals ``u`` (the last inputs of ``P``, the first outputs of ``Q``).
    ny : int
        Number of signals ``y`` (the last outputs of ``P``, the first inputs of ``Q``).
    """
    P = as_ss(P, "P")
    Q = as_ss(Q, "Q")
    if nu < 0 or ny < 0 or nu > P.ninputs or ny > P.noutputs:
        raise ModelError(f"star: P has {P.ninputs} inputs and {P.noutputs} outputs; cannot close nu={nu}, ny={ny}")
    if Q.ninputs < ny or Q.noutputs < nu:
        raise ModelError(f"star: Q must have at least ny={ny} inputs and nu={nu} outputs, "
                         f"got {Q.ninputs} inputs and {Q.noutputs} outputs")
    nP, nQ = P.nstates, Q.nstates
    m1, p1 = P.ninputs - nu, P.noutputs - ny
    m2, p2 = Q.ninputs - ny, Q.noutputs - nu
    Ap, Bp, Cp, Dp = (np.asarray(X, float) for X in (P.A, P.B, P.C, P.D))
    Aq, Bq, Cq, Dq = (np.asarray(X, float) for X in (Q.A, Q.B, Q.C, Q.D))
    B1, B2 = Bp[:, :m1], Bp[:, m1:]
    C1, C2 = Cp[:p1], Cp[p1:]
    D11, D12, D21, D22 = Dp[:p1, :m1], Dp[:p1, m1:], Dp[p1:, :m1], Dp[p1:, m1:]
    Bq1, Bq2 = Bq[:, :ny], Bq[:, ny:]
    Cq1, Cq2 = Cq[:nu], Cq[nu:]
    Q11, Q12, Q21, Q22 = Dq[:nu, :ny], Dq[:nu, ny:], Dq[nu:, :ny], Dq[nu:, ny:]
    # Solve the algebraic loop [u; y] = E^{-1} G [xP; xQ; wP; wQ].
    E = np.block([[np.eye(nu), -Q11], [-D22, np.eye(ny)]])
    # well posed iff I - D22*Q11 is invertible (the Schur complement of E); E's own
    # condition number would also grow with a large but harmless |Q11| when D22 = 0
    F = np.eye(ny) - D22 @ Q11
    if not (np.all(np.isfinite(Q11)) and np.all(np.isfinite(D22))) or (F.size and np.linalg.cond(F) > 1e12):
        raise IllPosedError("interconnection is not well posed: I - D22*DK is singular "
                            "(the loop through the feedthrough terms has no unique solution)")
    G = np.block([
        [np.zeros((nu, nP)), Cq1, np.zeros((nu, m1)), Q12],
        [C2, np.zeros((ny, nQ)), D21, np.zeros((ny, m2))],
    ])
    UY = np.linalg.solve(E, G) if E.size else G
    U, Y = UY[:nu], UY[nu:]
    # selectors for [xP; xQ; wP; wQ]
    N = nP + nQ + m1 + m2
    Sx = np.eye(N)[:nP]
    Sq = np.eye(N)[nP:nP + nQ]
    Sw1 = np.eye(N)[nP + nQ:nP + nQ + m1]
    Sw2 = np.eye(N)[nP + nQ + m1:]
    dxP = Ap @ Sx + B1 @ Sw1 + B2 @ U
    dxQ = Aq @ Sq + Bq1 @ Y + Bq2 @ Sw2
    zP = C1 @ Sx + D11 @ Sw1 + D12 @ U
    zQ = Cq2 @ Sq + Q21 @ Y + Q22 @ Sw2
    top = np.vstack([dxP, dxQ])
    bot = np.vstack([zP, zQ])
    nx = nP + nQ
    in_names = list(P.input_labels[:m1]) + list(Q.input_labels[ny:])
    out_names = list(P.output_labels[:p1]) + list(Q.output_labels[nu:])
    return ss(top[:, :nx], top[:, nx:], bot[:, :nx], bot[:, nx:],
              inputs=_unique(in_names), outputs=_unique(out_names))


def _unique(names):
    seen, out = {}, []
    for n in names:
        k = seen.get(n, 0)
        out.append(n if k == 0 else f"{n}_{k}")
        seen[n] = k + 1
    return out


def lft_lower(P, K, nmeas: int | None = None, ncon: int | None = None) -> ct.StateSpace:
    r"""Lower LFT :math:`\mathcal F_\ell(P, K) = P_{11} + P_{12}K(I - P_{22}K)^{-1}P_{21}`.

    ``K`` maps the last ``nmeas`` outputs of ``P`` to its last ``ncon`` inputs
    (defaults: the sizes of ``K``).  Same convention as :func:`control.hinfsyn`.

    Parameters
    ----------
    P : StateSpace or as accepted by :func:`as_ss`
        Generalised plant, inputs ``[w; u]`` and outputs ``[z; y]``.
    K : StateSpace or as accepted by :func:`as_ss`
        Controller from the ``nmeas`` measurements ``y`` to the ``ncon`` controls ``u``.
    nmeas : int, optional
        Number of measurements (the last outputs of ``P``); default: the inputs of ``K``.
    ncon : int, optional
        Number of controls (the last inputs of ``P``); default: the outputs of ``K``.

    Examples
    --------
    >>> from mutext.lti import ss, lft_lower
    >>> P = ss([[-1.0]], [[1.0, 1.0]], [[1.0], [1.0]], [[0.0, 0.0], [0.0, 0.0]])
    >>> CL = lft_lower(P, ss([], [], [], [[-1.0]]))     # static feedback u = -y
    >>> [round(float(p.real), 6) for p in CL.poles()]   # the pole moves from -1 to -2
    [-2.0]
    """
    K = as_ss(K, "K")
    nmeas = K.ninputs if nmeas is None else nmeas
    ncon = K.noutputs if ncon is None else ncon
    if K.ninputs != nmeas or K.noutputs != ncon:
        raise ModelError(f"K has {K.ninputs} inputs and {K.noutputs} outputs, "
                         f"but nmeas={nmeas}, ncon={ncon}")
    return star(P, K, ncon, nmeas)


def lft_upper(P, Delta, nrow: int | None = None, ncol: int | None = None) -> ct.StateSpace:
    r"""Upper LFT :math:`\mathcal F_u(P, \Delta) = P_{22} + P_{21}\Delta(I - P_{11}\Delta)^{-1}P_{12}`.

    ``Delta`` maps the first ``ncol`` outputs of ``P`` to its first ``nrow``
    inputs (defaults: the sizes of ``Delta``).

    Parameters
    ----------
    P : StateSpace or as accepted by :func:`as_ss`
        System with inputs ``[w_Delta; w]`` and outputs ``[z_Delta; z]``.
    Delta : StateSpace or as accepted by :func:`as_ss`
        The block closed around the first ``ncol`` outputs and ``nrow`` inputs of ``P``
        (a constant matrix is accepted).
    nrow : int, optional
        Number of outputs of ``Delta`` (the first inputs of ``P``); default: from ``Delta``.
    ncol : int, optional
        Number of inputs of ``Delta`` (the first outputs of ``P``); default: from ``Delta``.
    """
    P = as_ss(P, "P")
    Delta = as_ss(Delta, "Delta")
    nrow = Delta.noutputs if nrow is None else nrow
    ncol = Delta.ninputs if ncol is None else ncol
    if Delta.noutputs != nrow or Delta.ninputs != ncol:
        raise ModelError(f"Delta is {Delta.noutputs}x{Delta.ninputs}, expected {nrow}x{ncol}")
    # permute P so the Delta channels come last, then close them as a lower LFT
    m, p = P.ninputs, P.noutputs
    pin = list(range(nrow, m)) + list(range(nrow))
    pout = list(range(ncol, p)) + list(range(ncol))
    Pp = ss(P.A, np.asarray(P.B)[:, pin], np.asarray(P.C)[pout], np.asarray(P.D)[np.ix_(pout, pin)],
            inputs=[P.input_labels[i] for i in pin], outputs=[P.output_labels[i] for i in pout])
    return star(Pp, Delta, nrow, ncol)


def lft_matrix(M, Delta, nrow: int, ncol: int, upper: bool = True) -> np.ndarray:
    r"""LFT of constant (possibly complex) matrices.

    With ``upper=True``: :math:`M_{22} + M_{21}\Delta(I - M_{11}\Delta)^{-1}M_{12}` where
    ``M11`` is ``ncol x nrow`` (``Delta`` is ``nrow x ncol``); with ``upper=False``
    the lower LFT with ``M22`` of size ``ncol x nrow``.

    Parameters
    ----------
    M : (p, m) array_like
        The constant (real or complex) matrix.
    Delta : (nrow, ncol) array_like
        The block closed around ``M``.
    nrow, ncol : int
        Size of ``Delta``: ``nrow`` of ``M``'s inputs are driven by it, ``ncol`` of its
        outputs drive it.
    upper : bool, optional
        Close ``Delta`` around the first inputs/outputs (upper LFT, default) or the
        last ones (lower LFT).

    Examples
    --------
    >>> import numpy as np
    >>> from mutext.lti import lft_matrix
    >>> M = np.array([[0.5, 1.0], [1.0, 2.0]])
    >>> lft_matrix(M, [[1.0]], 1, 1)          # 2 + 1 * 1 / (1 - 0.5) * 1
    array([[4.]])
    """
    M = np.atleast_2d(np.asarray(M))
    Delta = np.atleast_2d(np.asarray(Delta))
    if Delta.shape != (nrow, ncol):
        raise ModelError(f"Delta must be {nrow}x{ncol}, got {Delta.shape[0]}x{Delta.shape[1]}")
    if upper:
        M11, M12 = M[:ncol, :nrow], M[:ncol, nrow:]
        M21, M22 = M[ncol:, :nrow], M[ncol:, nrow:]
        E = np.eye(ncol) - M11 @ Delta
        if np.linalg.cond(E) > 1e14:
            raise IllPosedError("I - M11*Delta is singular: the LFT is not well posed for this Delta")
        return M22 + M21 @ Delta @ np.linalg.solve(E, M12)
    p, m = M.shape
    M11, M12 = M[:p - ncol, :m - nrow], M[:p - ncol, m - nrow:]
    M21, M22 = M[p - ncol:, :m - nrow], M[p - ncol:, m - nrow:]
    E = np.eye(ncol) - M22 @ Delta
    if np.linalg.cond(E) > 1e14:
        raise IllPosedError("I - M22*Delta is singular: the LFT is not well posed for this Delta")
    return M11 + M12 @ Delta @ np.linalg.solve(E, M21)


# ----------------------------------------------------------------------------
# frequency response and norms
# ----------------------------------------------------------------------------

def freqresp(sys, omega) -> np.ndarray:
    r"""Frequency response ``G(j w)`` as an array of shape (noutputs, ninputs, len(omega)).

    ``omega`` in rad/s.  The states are first rescaled by
    :func:`scipy.linalg.matrix_balance` (powers of two, an exact similarity).
    Then, per frequency, :math:`X = (j\omega I - A)^{-1} B` is computed by one of
    two routes, chosen by what the result can be shown to satisfy:

    * **modal** (from 16 states up, when ``A`` is diagonalisable with an
      eigenvector matrix of condition below 1e8): :math:`X = V (j\omega I -
      \Lambda)^{-1} V^{-1} B`, checked by its componentwise (Oettli-Prager)
      backward error :math:`\max_{ij} |R_{ij}| / (|\omega||X| + |A||X| +
      |B|)_{ij}` with :math:`R = B - (j\omega I - A) X`.  Where it exceeds
      :math:`64\,n\,\epsilon`, one refinement step on the residual; where it
      still does (a resolvent too close to defective, eigenvectors too skewed
      for this frequency), that frequency is solved by the direct route.  A
      kept result is thus as accurate as a backward-stable solve, componentwise
      (which is what protects the slow states of a stiff system, where a
      normwise test against ``||A||`` would not), at :math:`O(n^2)` per
      frequency instead of :math:`O(n^3)`, computed for blocks of frequencies
      as matrix products (0.6x python-control's time at 100 states);
    * **direct**: a batched complex LU with partial pivoting.

    Why not a Hessenberg form: reducing the balanced ``A`` to Hessenberg form
    once (the textbook route) mixes the states by an orthogonal transformation
    whose backward error is ``eps * ||A_bal||`` in *every* entry.  On a stiff
    system (weight poles at -1e-6 rad/s in a loop with much faster modes)
    balancing spreads the state scales over 1e6..1e11 and that normwise error
    reaches the slow states: relative errors of 0.26 at DC on the near-axis
    closed loop of the tests, 2e5 with slycot's controller, where the routes
    above are right to 1e-9 and 2e-7 (checked against 50-digit ``mpmath``;
    ``benchmarks/bench_freqresp.py`` prints accuracy and time beside
    python-control's).

    Parameters
    ----------
    sys : StateSpace or as accepted by :func:`as_ss`
        The continuous-time system.
    omega : float or (N,) array_like
        Frequencies in rad/s (finite, non-negative).

    Examples
    --------
    >>> import numpy as np
    >>> from mutext.lti import ss, freqresp
    >>> G = ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]])     # 1/(s + 1)
    >>> H = freqresp(G, [0.0, 1.0])
    >>> H.shape
    (1, 1, 2)
    >>> np.round(np.abs(H[0, 0]), 4)                    # 1 and 1/sqrt(2)
    array([1.    , 0.7071])
    """
    sys = as_ss(sys)
    check_finite(sys)
    omega = _omega_vector(omega, "freqresp")
    A, B, C, D = (np.asarray(X, float) for X in (sys.A, sys.B, sys.C, sys.D))
    out = np.empty((D.shape[0], D.shape[1], omega.size), dtype=complex)
    if A.size == 0:
        out[:] = D[:, :, None]
        return out
    import scipy.linalg as sla
    # diagonal balancing (exact: powers of two) equilibrates the rows of jwI - A
    # for the pivoting; states of very different scale (a fast controller pole next
    # to slow structural modes) otherwise make the pivots depend on units
    _, (sc, _) = sla.matrix_balance(A, permute=False, separate=True)
    A, B, C = A / sc[:, None] * sc[None, :], B / sc[:, None], C * sc[None, :]
    n = A.shape[0]
    G = np.empty((C.shape[0], omega.size, B.shape[1]), dtype=complex)     # C X, frequency in the middle
    todo = np.ones(omega.size, bool)
    if n >= _MODAL_MIN_STATES:
        todo = _modal_response(A, B, C, omega, G)
    if todo.any():
        try:
            G[:, todo] = _direct_response(A, B, C, omega[todo])
        except np.linalg.LinAlgError:
            lam = np.linalg.eigvals(A)
            hit = [w for w in omega[todo] if np.min(np.abs(1j * w - lam)) <= 1e-12 * max(1.0, abs(w))]
            where = f" at {hit[0]:g} rad/s" if hit else ""
            raise ModelError(f"freqresp: the system has a pole on the imaginary axis{where}, on the frequency "
                             "grid (an undamped mode or an integrator at 0): its response is infinite there; "
                             "leave that frequency out or add damping") from None
    out[:] = G.transpose(0, 2, 1) + D[:, :, None]
    return out


def _omega_vector(omega, what: str) -> np.ndarray:
    """Frequencies as a 1-D array of finite real numbers (rad/s), or a :class:`ModelError` saying what is wrong."""
    try:
        w = np.asarray(omega, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"{what}: the frequencies must be real numbers (rad/s), got {type(omega).__name__}") \
            from None
    if w.ndim > 1:
        raise ModelError(f"{what}: the frequencies must be a 1-D array (rad/s), got shape {w.shape}")
    w = np.atleast_1d(w)
    if not np.all(np.isfinite(w)):
        bad = w[~np.isfinite(w)][0]
        raise ModelError(f"{what}: the frequencies must be finite, got {bad} at index "
                         f"{int(np.argmax(~np.isfinite(w)))}")
    return w


#: from this many states up the modal route is tried first (below it LU is as cheap)
_MODAL_MIN_STATES = 16

#: complex entries of one block of the modal route's (n, frequencies, m) arrays: small enough to
#: stay in cache and be recycled by the allocator (whole-grid temporaries of megabytes cost more in
#: page faults than in arithmetic), large enough that the products are efficient matrix products
_MODAL_BLOCK = 2 ** 14

#: the modal result is kept where its componentwise backward error is at most this times n eps
_BACKWARD_TOL = 64


def _direct_response(A, B, C, omega) -> np.ndarray:
    """``C (jwI - A)^-1 B`` for each w by a batched complex LU, shape (p, len(omega), m)."""
    n = A.shape[0]
    G = np.empty((C.shape[0], omega.size, B.shape[1]), dtype=complex)
    chunk = max(1, int(2 ** 16 // (n * n)))     # stacked matrices near 1 MB
    idx = np.arange(n)
    for s in range(0, omega.size, chunk):
        w = omega[s:s + chunk]
        M = np.broadcast_to(-A, (w.size, n, n)).astype(complex)
        M[:, idx, idx] += 1j * w[:, None]
        G[:, s:s + chunk] = np.moveaxis(C[None] @ np.linalg.solve(M, B[None]), 0, 1)
    return G


def _modal_response(A, B, C, omega, G) -> np.ndarray:
    """Fill ``G[:, k]`` with ``C X_k`` by the eigen-decomposition where the backward error of ``X_k`` is
    small; return where it was not.

    Frequencies are taken in blocks laid out (n, block, m), so that ``V Y``, ``A X``, ``|A| |X|`` and
    ``C X`` are each one matrix product over the whole block (``A X`` a real one on the real and
    imaginary parts side by side).
    """
    n, m = B.shape
    todo = np.ones(omega.size, bool)
    lam, V = np.linalg.eig(A)
    if not np.all(np.isfinite(lam)) or np.linalg.cond(V) > 1e8:
        return todo
    Vinv = np.linalg.inv(V)
    W = Vinv @ B
    absA, absB = np.abs(A), np.abs(B)
    tol = _BACKWARD_TOL * n * np.finfo(float).eps
    chunk = max(1, _MODAL_BLOCK // (n * max(m, 1)))
    for s in range(0, omega.size, chunk):
        w = omega[s:s + chunk]
        # a pole on the grid gives inf/NaN here: the check then fails and the direct route names it
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            Dinv = 1.0 / (1j * w[None, :] - lam[:, None])                  # (n, F)
            X = _modal_apply(V, Dinv, W)                                     # (n, F, m)
            R = _residual(A, B, w, X)
            ok = _backward_error_ok(w, X, R, absA, absB, tol)
            redo = np.flatnonzero(~ok)
            if redo.size:                                                   # one refinement step where needed
                Xr = X[:, redo] + _modal_apply(V, Dinv[:, redo], Vinv @ R[:, redo].reshape(n, -1), m)
                fixed = _backward_error_ok(w[redo], Xr, _residual(A, B, w[redo], Xr), absA, absB, tol)
                X[:, redo[fixed]] = Xr[:, fixed]
                ok[redo[fixed]] = True
        F = w.size
        G[:, s:s + F][:, ok] = (C @ X.reshape(n, -1)).reshape(C.shape[0], F, m)[:, ok]
        todo[s:s + F] = ~ok
    return todo


def _modal_apply(V, Dinv, W, m=None) -> np.ndarray:
    """``V diag(Dinv[:, k]) W_k`` for each column k of ``Dinv``, shape (n, F, m).

    ``W`` is either one (n, m) matrix for every k or the blocks side by side, (n, F*m)."""
    n, F = Dinv.shape
    if m is None:
        Y = Dinv[:, :, None] * W[:, None, :]
    else:
        Y = Dinv[:, :, None] * W.reshape(n, F, m)
    return (V @ Y.reshape(n, -1)).reshape(Y.shape)


def _residual(A, B, w, X) -> np.ndarray:
    """``B - (jwI - A) X_k`` for each k, X laid out (n, F, m); ``A X`` as one real matrix product."""
    n = X.shape[0]
    R = (A @ X.reshape(n, -1).view(float)).view(complex).reshape(X.shape)
    R -= X * (1j * w)[None, :, None]
    R += B[:, None, :]
    return R


def _backward_error_ok(w, X, R, absA, absB, tol) -> np.ndarray:
    """Whether each ``X_k`` has componentwise backward error at most ``tol``, given its residual ``R``.

    Componentwise (Oettli-Prager), not normwise: on a stiff system a residual
    small against ``||A||`` can still be large against a slow state's own row.
    The test is :math:`|R| \\le tol\\,(|\\omega||X| + |A||X| + |B|)` entry by
    entry (a zero bound then needs a zero residual; NaN fails).
    """
    n = X.shape[0]
    absX = np.abs(X)
    bound = (absA @ absX.reshape(n, -1)).reshape(X.shape)
    bound += np.abs(w)[None, :, None] * absX
    bound += absB[:, None, :]
    bound *= tol
    return (np.abs(R) <= bound).all(axis=2).all(axis=0)


def sigma_max(sys, omega) -> np.ndarray:
    """Largest singular value of ``G(j w)`` at each frequency (rad/s).

    Parameters
    ----------
    sys : StateSpace or as accepted by :func:`as_ss`
        The continuous-time system.
    omega : float or (N,) array_like
        Frequencies in rad/s.

    Examples
    --------
    >>> import numpy as np
    >>> from mutext.lti import ss, sigma_max
    >>> np.round(sigma_max(ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]]), [0.0, 1.0]), 4)
    array([1.    , 0.7071])
    """
    G = freqresp(sys, omega)
    if min(G.shape[:2]) == 0:
        return np.zeros(G.shape[2])
    return np.linalg.svd(np.moveaxis(G, -1, 0), compute_uv=False)[:, 0]


@dataclass
class Stability:
    """Result of :func:`stability`.

    Attributes
    ----------
    stable : bool
        Every pole has real part below ``-threshold`` (its own threshold).
    poles : ndarray
        Eigenvalues of the (balanced) state matrix.
    thresholds : ndarray
        Per pole: ``max(margin, 1e-12 |p|, 10 eps ||A_bal||_1)``.
    worst : complex
        The pole closest to failing (largest ``Re p + threshold``); ``nan`` without states.
    max_real_part : float
        Largest real part of any pole (``-inf`` without states).
    message : str
        What was found, naming the deciding pole, its real part and its threshold.
    """
    stable: bool
    poles: np.ndarray
    thresholds: np.ndarray
    worst: complex
    max_real_part: float
    message: str

    def __bool__(self):
        return self.stable


@validate_params({"margin": Real(lo=0)})
def stability(sys, margin: float = 0.0) -> Stability:
    r"""Scale-aware stability test of a continuous-time system, with the evidence.

    Pole :math:`p_i` of the state-balanced system (:func:`balance_states`)
    counts as stable when

    .. math::
        \operatorname{Re} p_i < -\max\bigl(\text{margin},\; 10^{-12}|p_i|,\;
        10\,\varepsilon\|A\|_1\bigr),

    the rule of :func:`_axis_poles` (used by :func:`hinf_norm`): a real part
    below ``1e-12`` of the pole's own magnitude, or within ten rounding units of
    ``A`` from the axis, cannot be told from zero in double precision, so such a
    pole is reported as undecidable, not as stable.  The threshold is relative to
    each pole and to the balanced ``A``, not to the largest pole: a weight pole
    at -1e-6 next to a controller pole at 1e8 rad/s is stable.  The raw-sign
    test it replaces called a pole at +1e-17 (rounding noise of an integrator)
    unstable or stable by chance.

    Parameters
    ----------
    sys : StateSpace
        Continuous-time system.
    margin : float
        Required distance of every pole from the imaginary axis (rad/s).

    Returns
    -------
    Stability
        The verdict (truthy when stable), the poles, their thresholds and a
        message naming the deciding pole.

    Examples
    --------
    >>> from mutext.lti import ss, stability
    >>> stability(ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]])).stable
    True
    >>> s = stability(ss([[0.0, 1.0], [-1.0, 0.0]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]]))   # undamped
    >>> s.stable, s.message[:26]
    (False, 'not decidably stable: pole')
    """
    sys = as_ss(sys)
    if sys.nstates == 0:
        return Stability(True, np.zeros(0, complex), np.zeros(0), complex(np.nan), -np.inf,
                         "no states: stable")
    bal, _ = balance_states(sys)
    A = np.asarray(bal.A, float)
    lam, tol = _axis_tolerance(A)
    thr = np.maximum(tol, float(margin))
    k = int(np.argmax(lam.real + thr))
    p, re, t = lam[k], float(lam[k].real), float(thr[k])
    stable = bool(np.all(lam.real < -thr))
    where = f"pole at s = {p:.6g} (real part {re:.3g}, threshold {-t:.3g})"
    if stable:
        msg = f"stable: all {lam.size} poles have real part below their threshold; the closest is the {where}"
    elif re > t:
        msg = f"unstable: {where} is in the right half plane"
    elif re >= -tol[k]:
        msg = (f"not decidably stable: {where} is within rounding of the imaginary axis "
               f"(|Re p| <= max(1e-12 |p|, 10 eps ||A_bal||) = {tol[k]:.3g})")
    else:
        msg = f"not stable with margin {margin:g}: {where}"
    return Stability(stable, lam, thr, complex(p), float(lam.real.max()), msg)


def is_stable(sys, margin: float = 0.0) -> bool:
    """True if every pole has real part < -margin and is decidably off the
    imaginary axis (scale-aware rule, see :func:`stability`).

    Parameters
    ----------
    sys : StateSpace or as accepted by :func:`as_ss`
        The continuous-time system.
    margin : float, optional
        Required distance of every pole to the left of the imaginary axis (1/s).
    """
    return stability(sys, margin).stable


def closed_loop_poles(P, K, nmeas: int, ncon: int) -> np.ndarray:
    """Poles of the closed loop F_l(P, K).

    Parameters
    ----------
    P : StateSpace or as accepted by :func:`as_ss`
        Generalised plant, inputs ``[w; u]`` and outputs ``[z; y]``.
    K : StateSpace or as accepted by :func:`as_ss`
        Controller from ``y`` to ``u``.
    nmeas : int
        Number of measurements ``y`` (the last outputs of ``P``).
    ncon : int
        Number of controls ``u`` (the last inputs of ``P``).
    """
    CL = lft_lower(P, K, nmeas, ncon)
    return np.linalg.eigvals(np.asarray(CL.A, float)) if CL.nstates else np.zeros(0)


def balance_states(sys, iterations: int = 50):
    """Diagonal state scaling that balances the rows and columns of [A B; C 0].

    Returns ``(scaled_sys, t)`` with ``x = diag(t) x_scaled``; the transfer
    function is unchanged.  Powers of two keep the scaling exact in floating
    point (an Osborne/Parlett-Reinsch iteration restricted to the states).

    Parameters
    ----------
    sys : StateSpace or as accepted by :func:`as_ss`
        The system to scale.
    iterations : int, optional
        Maximum number of sweeps over the states (stops earlier when no scale changes).
    """
    sys = as_ss(sys)
    A, B, C = (np.asarray(X, float).copy() for X in (sys.A, sys.B, sys.C))
    n = A.shape[0]
    t = np.ones(n)
    for _ in range(iterations):
        changed = False
        for i in range(n):
            r = np.linalg.norm(np.concatenate([np.delete(A[i], i), B[i]]))
            c = np.linalg.norm(np.concatenate([np.delete(A[:, i], i), C[:, i]]))
            if r == 0 or c == 0:
                continue
            f = 2.0 ** np.round(0.5 * np.log2(r / c))
            if f != 1.0:
                # x_i = f * x_i_new: row i divided by f, column i multiplied by f
                A[i, :] /= f
                B[i, :] /= f
                A[:, i] *= f
                C[:, i] *= f
                t[i] *= f
                changed = True
        if not changed:
            break
    out = ss(A, B, C, sys.D, inputs=sys.input_labels, outputs=sys.output_labels)
    return out, t


@dataclass
class HinfNorm:
    """Result of :func:`hinf_norm`.

    Attributes
    ----------
    value : float
        The norm (``inf`` for an unstable system or one with imaginary-axis poles,
        decided by the scale-aware rule of :func:`_axis_poles`).
    frequency : float
        A frequency (rad/s) where the peak is attained (``inf`` if at infinity).
    lower, upper : float
        Certified bracket: ``lower`` is a computed gain, ``upper`` a level at
        which the Hamiltonian has no imaginary-axis eigenvalue.
    iterations : int
    """
    value: float
    frequency: float
    lower: float
    upper: float
    iterations: int

    def __float__(self):
        return float(self.value)


def _hamiltonian(A, B, C, D, g):
    R = g * g * np.eye(D.shape[1]) - D.T @ D
    Ri = np.linalg.inv(R)
    Ah = A + B @ Ri @ D.T @ C
    return np.block([[Ah, B @ Ri @ B.T],
                     [-C.T @ (np.eye(D.shape[0]) + D @ Ri @ D.T) @ C, -Ah.T]])


def _axis_poles(A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    r"""Eigenvalues of ``A`` and a mask of those treated as on the imaginary axis.

    Scale-aware rule: pole :math:`p_i` is on the axis when

    .. math::
        |\operatorname{Re} p_i| \le \max\bigl(10^{-12} |p_i|,\;
        10\,\varepsilon \|A\|_1\bigr),

    i.e. its real part is negligible against *its own* magnitude, or it is within
    ten rounding units of ``A`` (the absolute accuracy of a well-conditioned
    eigenvalue) from the axis: an integrator or an undamped mode of a stiff
    system comes out with a real part of that size and either sign, and a stable
    pole that close to the axis cannot be told from an axis pole in double
    precision.  ``A`` should be balanced first (:func:`balance_states`), so that
    :math:`\|A\|` is that of the best-scaled coordinates.  The old rule,
    :math:`|\operatorname{Re} p| \le 10^{-12}\max_j|p_j|`, flagged well-determined
    stable poles at -1e-6 as soon as another pole passed 1e6 rad/s.  (A bound
    with each eigenvalue's condition number, :math:`\varepsilon\|A\|\kappa_i`, was
    tried and rejected: on graded matrices, slycot's controllers with poles near
    1e9, it is pessimistic by orders of magnitude and flagged poles at -11 rad/s.)
    """
    lam, tol = _axis_tolerance(A)
    return lam, np.abs(lam.real) <= tol


def _axis_tolerance(A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues of ``A`` and, per eigenvalue, the distance from the imaginary axis
    below which its sign is not decided (see :func:`_axis_poles`)."""
    if A.size == 0:
        return np.zeros(0, complex), np.zeros(0)
    lam = np.linalg.eigvals(A)
    return lam, np.maximum(1e-12 * np.abs(lam), 10 * np.finfo(float).eps * np.linalg.norm(A, 1))


@validate_params({"rtol": Real(0, 1, closed="neither")})
def hinf_norm(sys, rtol: float = 1e-10, *, require_stable: bool = True) -> HinfNorm:
    r"""H-infinity norm :math:`\sup_\omega \bar\sigma(G(j\omega))` of a continuous-time system.

    Two-step (Bruinsma-Steinbuch [BS]_) iteration on the Hamiltonian

    .. math::
        H(\gamma) = \begin{bmatrix} A + BR^{-1}D^TC & BR^{-1}B^T \\
        -C^T(I + DR^{-1}D^T)C & -(A + BR^{-1}D^TC)^T \end{bmatrix},
        \quad R = \gamma^2 I - D^TD,

    which has an eigenvalue :math:`j\omega` exactly when :math:`\gamma` is a
    singular value of :math:`G(j\omega)` [BBK]_.  Each step evaluates the gain at
    the midpoints of the intervals where the gain exceeds the current lower
    bound, which converges quadratically.

    Parameters
    ----------
    sys : StateSpace
    rtol : float
        Relative width of the final bracket ``[lower, upper]``.
    require_stable : bool
        If True (default), an unstable system has norm ``inf``.  If False the
        L-infinity norm (peak gain on the imaginary axis) is returned, which is
        finite when no pole lies on the imaginary axis.

    The gain is computed on ``G / s`` with ``s`` the size of ``B``, ``C`` and
    ``D`` (an exact rescaling), so systems scaled by 1e-160 or 1e300 give their
    norm, not an overflow; a norm beyond the largest double is ``inf``.

    Examples
    --------
    >>> from mutext.lti import ss, hinf_norm
    >>> G = ss([[0.0, 1.0], [-1.0, -0.2]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]])   # 1/(s^2 + 0.2 s + 1)
    >>> r = hinf_norm(G)
    >>> round(r.value, 3), round(r.frequency, 3)       # the resonance peak 1/(2 zeta sqrt(1 - zeta^2))
    (5.025, 0.99)
    """
    sys = as_ss(sys)
    check_finite(sys)
    B0, C0, D0 = (np.asarray(X, float) for X in (sys.B, sys.C, sys.D))
    sB = float(np.max(np.abs(B0))) if B0.size else 0.0
    sC = float(np.max(np.abs(C0))) if C0.size else 0.0
    sD0 = float(np.max(np.abs(D0))) if D0.size else 0.0
    logs = [x for x in ((np.log(sB) + np.log(sC)) if sB > 0 and sC > 0 else -np.inf,
                        np.log(sD0) if sD0 > 0 else -np.inf) if np.isfinite(x)]
    if logs and abs(max(logs)) > 30:
        # rescale to gains of order one: G = exp(ls) G', exactly, with |B'|, |C'|, |D'| <= 1
        ls = max(logs)
        Bs = B0 / sB if sB > 0 else B0
        Cs = C0 / sC * np.exp(np.log(sB) + np.log(sC) - ls) if sB > 0 and sC > 0 else C0 * 0.0
        Ds = D0 * np.exp(-ls)
        r = hinf_norm(ss(sys.A, Bs, Cs, Ds), rtol, require_stable=require_stable)
        with np.errstate(over="ignore"):
            f = np.exp(ls)
            return HinfNorm(float(r.value * f), r.frequency, float(r.lower * f), float(r.upper * f), r.iterations)
    D = np.asarray(sys.D, float)
    sD = np.linalg.norm(D, 2) if D.size else 0.0
    if sys.nstates == 0:
        return HinfNorm(sD, np.inf, sD, sD, 0)
    bal, _ = balance_states(sys)
    A, B, C = (np.asarray(X, float) for X in (bal.A, bal.B, bal.C))
    poles, on_axis = _axis_poles(A)
    if np.any(on_axis):
        return HinfNorm(np.inf, float(np.min(np.abs(poles[on_axis].imag))), np.inf, np.inf, 0)
    if require_stable and np.any(poles.real > 0):
        return HinfNorm(np.inf, np.nan, np.inf, np.inf, 0)
    if np.linalg.norm(B) == 0 or np.linalg.norm(C) == 0:
        return HinfNorm(sD, np.inf, sD, sD, 0)

    # initial lower bound: gain at 0, infinity and near each pole's frequency
    cand = [0.0] + [abs(p) for p in poles] + [abs(p.imag) for p in poles if p.imag != 0]
    cand = np.unique(np.array(cand))
    s = sigma_max(bal, cand)
    k = int(np.argmax(s))
    lower, wpk = float(s[k]), float(cand[k])
    if sD > lower:
        lower, wpk = sD, np.inf
    if lower == 0.0:
        return HinfNorm(0.0, 0.0, 0.0, 0.0, 0)
    it = 0
    while True:
        it += 1
        g = (1.0 + 2.0 * rtol) * lower
        ev = np.linalg.eigvals(_hamiltonian(A, B, C, D, g))
        # generous: near a flat peak the crossing eigenvalues are nearly double and their
        # computed real parts are O(sqrt(eps)); spurious candidates are harmless because
        # each one is checked by evaluating the gain
        tol_im = 1e-6 * max(1.0, np.max(np.abs(ev)))
        w = np.sort(np.unique(np.round(np.abs(ev[np.abs(ev.real) < tol_im].imag), 14)))
        if w.size == 0 or it > 60:
            return HinfNorm(lower, wpk, lower, g, it)
        if w.size == 1:
            mids = w
        else:
            mids = np.concatenate([0.5 * (w[:-1] + w[1:]),
                                   np.sqrt(np.maximum(w[:-1], 1e-300) * w[1:])])
        sm = sigma_max(bal, mids)
        j = int(np.argmax(sm))
        if sm[j] <= lower * (1 + 1e-15):
            # imaginary eigenvalues are numerical artefacts at the peak: converged
            return HinfNorm(lower, wpk, lower, g, it)
        lower, wpk = float(sm[j]), float(mids[j])
