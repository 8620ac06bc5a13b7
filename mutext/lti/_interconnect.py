"""Interconnection: the Redheffer star product and the lower and upper LFTs of systems and of matrices
([ZDG]_ ch. 10)."""
from __future__ import annotations

import control as ct
import numpy as np

from ..errors import IllPosedError, ModelError
from ._ss import as_ss, ss


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
