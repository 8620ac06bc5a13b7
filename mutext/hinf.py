r"""H-infinity synthesis: Riccati equations and linear matrix inequalities.

Given a generalized plant

.. math::
    P:\quad \dot x = Ax + B_1 w + B_2 u,\quad z = C_1x + D_{11}w + D_{12}u,\quad
    y = C_2x + D_{21}w + D_{22}u,

find a stabilizing controller ``u = K y`` that minimises the H-infinity norm
of the closed loop :math:`w \to z`.

Method
------
1. *Optimal level* (Gahinet and Apkarian [GA]_, Theorem 4.3): a controller with
   closed-loop norm below :math:`\gamma` exists iff there are symmetric
   :math:`R, S` with

   .. math::
       \begin{bmatrix} N_R & 0\\ 0 & I\end{bmatrix}^T
       \begin{bmatrix} AR + RA^T & RC_1^T & B_1\\ C_1R & -\gamma I & D_{11}\\
       B_1^T & D_{11}^T & -\gamma I\end{bmatrix}
       \begin{bmatrix} N_R & 0\\ 0 & I\end{bmatrix} \prec 0,\qquad
       \begin{bmatrix} N_S & 0\\ 0 & I\end{bmatrix}^T
       \begin{bmatrix} A^TS + SA & SB_1 & C_1^T\\ B_1^TS & -\gamma I & D_{11}^T\\
       C_1 & D_{11} & -\gamma I\end{bmatrix}
       \begin{bmatrix} N_S & 0\\ 0 & I\end{bmatrix} \prec 0,\qquad
       \begin{bmatrix} R & I\\ I & S\end{bmatrix} \succeq 0,

   where :math:`N_R` and :math:`N_S` span the null spaces of
   :math:`[B_2^T\ D_{12}^T]` and :math:`[C_2\ D_{21}]`.  These are linear in
   :math:`(R, S, \gamma)`, so the optimal level is a single semidefinite
   program (no bisection).  No rank condition on :math:`D_{12}, D_{21}` is
   needed: singular problems that the Riccati method refuses are handled.
   For *regular* problems (:math:`D_{12}` full column rank, :math:`D_{21}`
   full row rank) the level is found instead by bisection on the exact
   Riccati conditions of Zhou, Doyle and Glover [ZDG]_ Theorem 17.1
   (:func:`riccati_feasible`, the gamma iteration of the Riccati method): two
   Hamiltonian Schur forms per step, about 40 steps to 1e-10, a fraction of a
   second at 40 states where the LMIs take minutes.  The LMIs take over where
   that iteration finds no level, and remain the route for singular problems
   (``method="lmi"`` forces them).
2. *Controller* at a level slightly above the optimum (``backoff``): the
   central controller of Glover and Doyle from the Riccati solutions
   :math:`X_\infty, Y_\infty` (:func:`central_controller`, in descriptor
   form) where they exist at that level; for singular problems the central
   controllers of regularised plants (:math:`\epsilon u` appended to ``z``,
   :math:`\epsilon v` added to ``y``) for decreasing :math:`\epsilon`; and the
   LMI reconstruction from the linearising change of variables of Scherer,
   Gahinet and Chilali [SGC]_, with an objective that keeps :math:`I - XY`
   well conditioned so the controller has no needlessly fast poles.
3. *Independent check* of every candidate: the closed loop is rebuilt from
   ``P`` and ``K``, its stability decided by the scale-aware rule of
   :func:`mutext.lti.stability`, and its norm recomputed by our Hamiltonian
   algorithm (:func:`mutext.lti.hinf_norm`), by SLICOT's ``AB13DD`` (through
   slycot) and on a frequency grid.  The first controller that achieves its
   target level is returned (``HinfResult.construction`` says which).

Numerics: the plant's states are balanced by a diagonal similarity
(powers of two) and the control and measurement channels normalised before
the LMIs are formed; the two-mass plant of the thesis needs this (its
optimal level is off by about 3 % without it).

References
----------
.. [GA] P. Gahinet and P. Apkarian, "A linear matrix inequality approach to
   H-infinity control", *Int. J. Robust Nonlinear Control* 4 (1994) 421-448.
.. [SGC] C. Scherer, P. Gahinet and M. Chilali, "Multiobjective
   output-feedback control via LMI optimization", *IEEE TAC* 42 (1997) 896-911.
.. [ZDG] K. Zhou, J. C. Doyle and K. Glover, *Robust and Optimal Control*,
   Prentice Hall, 1996, ch. 16-17.
"""
from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field, replace

import control as ct
import cvxpy as cp
import numpy as np
import scipy.linalg as sla

from .errors import IllPosedError, InfeasibleError, ModelError, SolverError
from .lti import as_ss, balance_states, check_finite, hinf_norm, lft_lower, sigma_max, ss, stability

__all__ = ["hinfsyn", "HinfResult", "check_plant", "PlantParts", "slycot_hinf_norm", "slycot_hinfsyn",
           "SlycotReference", "central_controller", "riccati_feasible"]


# ----------------------------------------------------------------------------
# plant partition and assumptions
# ----------------------------------------------------------------------------

@dataclass
class PlantParts:
    """The blocks of a generalized plant (all 2-D float arrays)."""
    A: np.ndarray
    B1: np.ndarray
    B2: np.ndarray
    C1: np.ndarray
    C2: np.ndarray
    D11: np.ndarray
    D12: np.ndarray
    D21: np.ndarray
    D22: np.ndarray

    @property
    def n(self):
        return self.A.shape[0]

    @property
    def sizes(self):
        """(n, nw, nu, nz, ny)."""
        return self.A.shape[0], self.B1.shape[1], self.B2.shape[1], self.C1.shape[0], self.C2.shape[0]


def _partition(P: ct.StateSpace, nmeas: int, ncon: int) -> PlantParts:
    A, B, C, D = (np.asarray(X, float) for X in (P.A, P.B, P.C, P.D))
    nw, nz = P.ninputs - ncon, P.noutputs - nmeas
    return PlantParts(A, B[:, :nw], B[:, nw:], C[:nz], C[nz:],
                      D[:nz, :nw], D[:nz, nw:], D[nz:, :nw], D[nz:, nw:])


def _uncontrollable_modes(A, B, tol=1e-9):
    """Eigenvalues of A in the closed right half plane that (A, B) cannot move (PBH test).

    Scale-invariant: the columns of B are normalised and A - lam I is divided by
    the norm of A, so multiplying A, B or single inputs by a constant does not
    change the answer (an absolute tolerance declared a plant with B scaled by
    1e-8 not stabilizable)."""
    n = A.shape[0]
    normA = float(np.linalg.norm(A, 2)) if A.size else 0.0
    sa = normA if normA > 0 else 1.0
    cb = np.linalg.norm(B, axis=0) if B.size else np.zeros(B.shape[1] if B.ndim == 2 else 0)
    Bn = B[:, cb > 0] / cb[cb > 0] if B.size else B
    bad = []
    for lam in np.linalg.eigvals(A):
        if lam.real < -1e-9 * max(abs(lam), 1e-3 * sa):
            continue
        M = np.hstack([(A - lam * np.eye(n)) / sa, Bn])
        smin = np.linalg.svd(M, compute_uv=False)[-1] if M.size else 0.0
        if smin < tol:
            bad.append(lam)
    return bad


def _axis_rank_losses(parts: PlantParts, tol: float = 1e-9) -> list[tuple[str, str]]:
    r"""Where the Riccati route's rank conditions fail on the imaginary axis.

    The central controller needs :math:`[A - j\omega I,\ B_2;\ C_1,\ D_{12}]` of full column
    rank and :math:`[A - j\omega I,\ B_1;\ C_2,\ D_{21}]` of full row rank at every
    :math:`\omega` (Zhou, Doyle and Glover 1996, sec. 17.1).  Checked at the frequencies where
    they can fail: the imaginary-axis eigenvalues of :math:`A` and, for square invertible
    :math:`D_{12}` or :math:`D_{21}`, those of :math:`A - B_2 D_{12}^{-1} C_1` or
    :math:`A - B_1 D_{21}^{-1} C_2` (the invariant zeros).  A mode on the axis that w cannot
    reach while it reaches y (``B1 = 0`` on that mode) is the common case."""
    A, n = parts.A, parts.A.shape[0]
    if n == 0:
        return []
    sa = max(float(np.linalg.norm(A, 2)), 1.0)

    def axis(M):
        ev = np.linalg.eigvals(M) if M.size else np.zeros(0)
        return [lam for lam in ev if abs(lam.real) <= 1e-9 * max(abs(lam), 1e-3 * sa)]
    out = []
    for what, B, C, D, col in (("[A - jwI, B2; C1, D12]", parts.B2, parts.C1, parts.D12, True),
                               ("[A - jwI, B1; C2, D21]", parts.B1, parts.C2, parts.D21, False)):
        cands = axis(A)
        if D.shape[0] == D.shape[1] and D.size and np.linalg.cond(D) < 1e12:
            cands += axis(A - B @ np.linalg.solve(D, C))
        bad = []
        for lam in sorted({complex(round(c.real, 12), round(c.imag, 9)) for c in cands}, key=lambda c: c.imag):
            M = np.block([[(A - lam * np.eye(n)) / sa, B], [C, D]])
            sv = np.linalg.svd(M, compute_uv=False)
            need = M.shape[1] if col else M.shape[0]
            if need > min(M.shape) or sv[need - 1] < tol * max(sv[0], 1e-300):
                bad.append(lam)
        if bad:
            out.append((what, ", ".join(f"s = {b.imag:+.6g}j" for b in bad)))
    return out


def _labels(P, kind):
    try:
        return list(P.input_labels if kind == "in" else P.output_labels)
    except AttributeError:  # pragma: no cover
        return []


def check_plant(P, nmeas: int, ncon: int) -> tuple[ct.StateSpace, PlantParts, list[str]]:
    """Validate a generalized plant for H-infinity synthesis.

    Returns ``(P, parts, notes)`` where ``notes`` lists properties that are
    allowed but worth knowing (singular ``D12``/``D21``).  Raises
    :class:`ModelError` for malformed input (sizes, non-finite entries) and
    :class:`IllPosedError` when no stabilizing controller can exist.
    """
    for name, v in (("nmeas", nmeas), ("ncon", ncon)):
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)) or v < 1:
            raise ModelError(f"{name} must be a positive integer, got {v!r}")
    P = as_ss(P, "P")
    check_finite(P, "P")
    if ncon >= P.ninputs:
        raise ModelError(f"ncon={ncon} but P has only {P.ninputs} inputs: "
                         "at least one exogenous input w must remain")
    if nmeas >= P.noutputs:
        raise ModelError(f"nmeas={nmeas} but P has only {P.noutputs} outputs: "
                         "at least one performance output z must remain")
    parts = _partition(P, nmeas, ncon)
    notes = []
    # a control input that moves neither the state nor z, or a measurement that
    # sees neither the state nor w, means the port counts are wrong (a different
    # problem would be solved silently)
    ins, outs = _labels(P, "in"), _labels(P, "out")
    Bu = np.vstack([parts.B2, parts.D12])
    Cy = np.hstack([parts.C2, parts.D21])
    ref_in = max(float(np.abs(np.vstack([np.hstack([parts.B1, parts.B2]),
                                          np.hstack([parts.D11, parts.D12])])).max(initial=0.0)), 1e-300)
    ref_out = max(float(np.abs(np.hstack([np.vstack([parts.C1, parts.C2]),
                                          np.vstack([parts.D11, parts.D21])])).max(initial=0.0)), 1e-300)
    for j in range(ncon):
        if np.abs(Bu[:, j]).max(initial=0.0) <= 1e-14 * ref_in:
            k = P.ninputs - ncon + j
            lab = f" ('{ins[k]}')" if k < len(ins) else ""
            raise ModelError(f"ncon={ncon}: control input {k + 1}{lab} of P moves neither the state nor a "
                             f"performance output (its columns of B2 and D12 are zero); the last ncon inputs "
                             f"of P are taken as controls -- is ncon right? (inputs: {', '.join(ins)})")
    for i in range(nmeas):
        if np.abs(Cy[i]).max(initial=0.0) <= 1e-14 * ref_out:
            k = P.noutputs - nmeas + i
            lab = f" ('{outs[k]}')" if k < len(outs) else ""
            raise ModelError(f"nmeas={nmeas}: measurement {k + 1}{lab} of P sees neither the state nor an "
                             f"exogenous input (its rows of C2 and D21 are zero); the last nmeas outputs of P "
                             f"are taken as measurements -- is nmeas right? (outputs: {', '.join(outs)})")
    if parts.n:
        # PBH tests in state coordinates balanced for (A, B2, C2): the test is then
        # invariant to the units of the states (states scaled by 1e-5..1e5 made
        # well-controllable modes look uncontrollable to the fixed tolerance)
        bal, _ = balance_states(ss(parts.A, parts.B2, parts.C2, parts.D22))
        Ab, B2b, C2b = (np.asarray(X, float) for X in (bal.A, bal.B, bal.C))
        bad = _uncontrollable_modes(Ab, B2b)
        if bad:
            raise IllPosedError(
                "(A, B2) is not stabilizable: the mode(s) at s = "
                + ", ".join(f"{b:.6g}" for b in bad)
                + " are unstable (or on the imaginary axis) and cannot be moved by the control input u")
        bad = _uncontrollable_modes(Ab.T, C2b.T)
        if bad:
            raise IllPosedError(
                "(C2, A) is not detectable: the mode(s) at s = "
                + ", ".join(f"{b:.6g}" for b in bad)
                + " are unstable (or on the imaginary axis) and invisible in the measurement y")
    for what, axis in _axis_rank_losses(parts):
        notes.append(f"{what} loses rank on the imaginary axis at {axis}: outside the Riccati method's "
                     "assumptions; solved by the LMI route. The optimal level may only be approached.")
    r12 = np.linalg.matrix_rank(parts.D12, tol=1e-12 * max(1.0, np.abs(parts.D12).max(initial=0)))
    r21 = np.linalg.matrix_rank(parts.D21, tol=1e-12 * max(1.0, np.abs(parts.D21).max(initial=0)))
    if r12 < ncon:
        notes.append(f"D12 does not have full column rank (rank {r12} < ncon={ncon}): singular problem, "
                     "outside the Riccati method's assumptions; solved by the LMI route. The optimal "
                     "level may only be approached, with controller gains that grow as gamma nears it.")
    if r21 < nmeas:
        notes.append(f"D21 does not have full row rank (rank {r21} < nmeas={nmeas}): singular problem, "
                     "outside the Riccati method's assumptions; solved by the LMI route. The optimal "
                     "level may only be approached, with controller gains that grow as gamma nears it.")
    return P, parts, notes


# ----------------------------------------------------------------------------
# scaling
# ----------------------------------------------------------------------------

def _scale(parts: PlantParts):
    """Balance states, rescale time, normalise the w -> z gain and the u and y channels.

    Returns ``(scaled parts, su, sy, t, alpha, c0)`` with ``u = diag(su) u_s``,
    ``y_s = diag(sy) y``, the frequency axis rescaled by ``alpha`` (see
    :func:`_time_scale`) and w, z scaled so that the level of the scaled plant
    is the level of the original divided by ``c0``.  Every factor is a power of
    two and the steps are ordered so that multiplying the plant's matrices by
    constants (units, time scale) gives the same scaled plant: the answer is
    scale-invariant (multiplying every matrix by 1e8 used to move the level).
    """
    p = parts
    n, nw, nu, nz, ny = p.sizes
    B = np.hstack([p.B1, p.B2])
    C = np.vstack([p.C1, p.C2])
    D = np.block([[p.D11, p.D12], [p.D21, p.D22]])
    bal, t = balance_states(ss(p.A, B, C, D)) if n else (ss(p.A, B, C, D), np.ones(0))
    A, B, C = (np.asarray(X, float) for X in (bal.A, bal.B, bal.C))
    work = PlantParts(A, B[:, :nw], B[:, nw:], C[:nz], C[nz:], p.D11, p.D12, p.D21, p.D22)
    # frequencies of order one: the LMI entries A R + R A^T and the gamma blocks
    # are then of comparable size
    alpha = 1.0
    mags = np.abs(np.linalg.eigvals(A)) if n else np.zeros(0)
    if mags.size and mags.max() > 0:
        alpha = float(2.0 ** np.round(np.log2(mags.max())))
        work = _time_scale(work, alpha)
    # w -> z gain of order one (a rough, coordinate-free estimate); done before
    # the u, y normalisation so that the latter does not depend on the units of z, w
    g_est = max(float(np.linalg.norm(work.D11, 2)) if work.D11.size else 0.0,
                (float(np.linalg.norm(work.C1, 2)) * float(np.linalg.norm(work.B1, 2))) if n else 0.0)
    c0 = float(2.0 ** np.round(np.log2(g_est))) if g_est > 0 and np.isfinite(g_est) else 1.0
    if c0 != 1.0:
        work = _transform(work, np.eye(n), c0)
    cu = np.linalg.norm(np.vstack([work.B2, work.D12]), axis=0)
    su = np.where(cu > 0, 2.0 ** -np.round(np.log2(np.where(cu > 0, cu, 1.0))), 1.0)
    ry = np.linalg.norm(np.hstack([work.C2, work.D21]), axis=1)
    sy = np.where(ry > 0, 2.0 ** -np.round(np.log2(np.where(ry > 0, ry, 1.0))), 1.0)
    w = work
    scaled = PlantParts(w.A, w.B1, w.B2 * su, w.C1, w.C2 * sy[:, None], w.D11, w.D12 * su,
                        w.D21 * sy[:, None], (w.D22 * su) * sy[:, None])
    return scaled, su, sy, t, alpha, c0


# ----------------------------------------------------------------------------
# the LMIs
# ----------------------------------------------------------------------------

def _sym(E):
    return 0.5 * (E + E.T)


_TIGHT = {"max_iter": 400}
_LOOSE = {"tol_gap_abs": 1e-6, "tol_gap_rel": 1e-6, "tol_feas": 1e-7, "max_iter": 400}


def _solve(prob: cp.Problem, solver: str, what: str, gamma_hint=None, tight: bool = True):
    opts = (_TIGHT if tight else _LOOSE) if solver.upper() == "CLARABEL" else {}
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            prob.solve(solver=solver, **opts)
    except cp.error.SolverError as exc:
        raise SolverError(f"{what}: solver {solver} failed ({exc})") from None
    status = prob.status
    if status in (cp.INFEASIBLE, cp.INFEASIBLE_INACCURATE):
        at = f" at gamma={gamma_hint:.6g}" if gamma_hint is not None else ""
        raise InfeasibleError(f"{what}: LMI infeasible{at} (solver status '{status}')")
    if status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE):
        raise SolverError(f"{what}: solver {solver} returned status '{status}'")
    return status


def _optimal_level(p: PlantParts, solver: str, tight: bool = True):
    """Gahinet-Apkarian LMIs: minimise gamma over (R, S)."""
    n, nw, nu, nz, ny = p.sizes
    R = cp.Variable((n, n), symmetric=True)
    S = cp.Variable((n, n), symmetric=True)
    g = cp.Variable()
    NR = sla.null_space(np.hstack([p.B2.T, p.D12.T]))
    NS = sla.null_space(np.hstack([p.C2, p.D21]))
    Iw, Iz, In = np.eye(nw), np.eye(nz), np.eye(n)
    M1 = cp.bmat([[p.A @ R + R @ p.A.T, R @ p.C1.T, p.B1],
                  [p.C1 @ R, -g * Iz, p.D11],
                  [p.B1.T, p.D11.T, -g * Iw]])
    M2 = cp.bmat([[p.A.T @ S + S @ p.A, S @ p.B1, p.C1.T],
                  [p.B1.T @ S, -g * Iw, p.D11.T],
                  [p.C1, p.D11, -g * Iz]])
    T1 = sla.block_diag(NR, Iw)
    T2 = sla.block_diag(NS, Iz)
    cons = [_sym(T1.T @ M1 @ T1) << 0, _sym(T2.T @ M2 @ T2) << 0,
            cp.bmat([[R, In], [In, S]]) >> 0]
    prob = cp.Problem(cp.Minimize(g), cons)
    status = _solve(prob, solver, "H-infinity optimal level", tight=tight)
    return float(g.value), R.value, S.value, status


def _transform(p: PlantParts, T: np.ndarray, c: float = 1.0) -> PlantParts:
    """The plant in state coordinates x = T x_new with w and z both scaled by
    1/sqrt(c) (so the w -> z gain, and the optimal level, are divided by c;
    the controller is unchanged and the LMI solutions R, S are invariant)."""
    Ti = np.linalg.inv(T)
    r = 1.0 / np.sqrt(c)
    return PlantParts(Ti @ p.A @ T, r * (Ti @ p.B1), Ti @ p.B2, r * (p.C1 @ T), p.C2 @ T,
                      p.D11 / c, r * p.D12, r * p.D21, p.D22)


def _balancing_transform(R: np.ndarray, S: np.ndarray) -> np.ndarray | None:
    """T with T^-1 R T^-T = T^T S T = diag(sigma): the coordinates in which the
    two LMI solutions are equal and diagonal (like a balanced realization of
    Gramians).  Returns None if R or S is not numerically positive definite."""
    try:
        Lr = np.linalg.cholesky(_sym(R))
        Ls = np.linalg.cholesky(_sym(S))
    except np.linalg.LinAlgError:
        return None
    _, sv, Vt = np.linalg.svd(Ls.T @ Lr)
    if sv[-1] <= 0:
        return None
    return Lr @ Vt.T @ np.diag(sv ** -0.5)


def _controller_at(p: PlantParts, gK: float, solver: str, bound: float = 1e4,
                   objective: str = "margin", gscale: float = 1.0):
    """Scherer-Gahinet-Chilali LMI at fixed level gK; returns (Ak, Bk, Ck, Dk, info).

    Maximises t in [[Y, tI], [tI, X]] >= 0 with X, Y bounded, which keeps
    I - XY away from singular (no needlessly fast controller poles).
    """
    n, nw, nu, nz, ny = p.sizes
    X = cp.Variable((n, n), symmetric=True)
    Y = cp.Variable((n, n), symmetric=True)
    Ah = cp.Variable((n, n))
    Bh = cp.Variable((n, ny))
    Ch = cp.Variable((nu, n))
    Dh = cp.Variable((nu, ny))
    t = cp.Variable()
    A, B1, B2, C1, C2, D11, D12, D21 = p.A, p.B1, p.B2, p.C1, p.C2, p.D11, p.D12, p.D21
    L11 = A @ Y + B2 @ Ch
    L11 = L11 + L11.T
    L21 = Ah + (A + B2 @ Dh @ C2).T
    L22 = X @ A + Bh @ C2
    L22 = L22 + L22.T
    L31 = (B1 + B2 @ Dh @ D21).T
    L32 = (X @ B1 + Bh @ D21).T
    L41 = C1 @ Y + D12 @ Ch
    L42 = C1 + D12 @ Dh @ C2
    L43 = D11 + D12 @ Dh @ D21
    Iw, Iz, In = np.eye(nw), np.eye(nz), np.eye(n)
    L = cp.bmat([[L11, L21.T, L31.T, L41.T],
                 [L21, L22, L32.T, L42.T],
                 [L31, L32, -gK * Iw, L43.T],
                 [L41, L42, L43, -gK * Iz]])
    # Chebyshev-centre-like point: the smallest margin of the two LMIs is
    # maximised, so neither the closed-loop bounded-real inequality nor the
    # coupling [[Y, I], [I, X]] > 0 sits on its boundary (either one tight makes
    # the reconstructed controller fragile).  X, Y are bounded to fix the scale.
    ntot = L.shape[0]
    if objective == "margin":
        cons = [_sym(L) << -t * np.eye(ntot),
                cp.bmat([[Y, In], [In, X]]) >> t * np.eye(2 * n),
                X << bound * In, Y << bound * In]
    else:  # "coupling": keep I - XY far from singular, main LMI non-strict
        cons = [_sym(L) << 0,
                cp.bmat([[Y, t * In], [t * In, X]]) >> 0,
                X << bound * In, Y << bound * In]
    prob = cp.Problem(cp.Maximize(t), cons)
    status = _solve(prob, solver, "H-infinity controller", gamma_hint=gK * gscale)
    if t.value is None or (objective == "margin" and t.value <= 0):
        raise InfeasibleError(f"H-infinity controller: no strictly feasible point at gamma={gK * gscale:.6g} "
                              f"(margin {t.value})")
    Xv, Yv = X.value, Y.value
    Ahv, Bhv, Chv, Dhv = Ah.value, Bh.value, Ch.value, Dh.value
    # U V^T = I - X Y, split by SVD so both factors are equally conditioned
    Wl, sv, Wr = np.linalg.svd(In - Xv @ Yv)
    if sv.size and sv[-1] <= 1e-14 * max(1.0, sv[0]):
        raise SolverError(f"controller reconstruction failed at gamma={gK * gscale:.6g}: I - XY is singular")
    U = Wl * np.sqrt(sv)
    V = Wr.T * np.sqrt(sv)
    Dk = Dhv
    Ck = np.linalg.solve(V, (Chv - Dk @ C2 @ Yv).T).T
    Bk = np.linalg.solve(U, Bhv - Xv @ B2 @ Dk)
    inner = Ahv - Xv @ (A + B2 @ Dk @ C2) @ Yv - Xv @ B2 @ Ck @ V.T - U @ Bk @ C2 @ Yv
    Ak = np.linalg.solve(V, np.linalg.solve(U, inner).T).T
    info = {"t": float(t.value), "cond_I_minus_XY": float(sv[0] / sv[-1]) if sv.size else 1.0,
            "status": status}
    return Ak, Bk, Ck, Dk, info


def _quasi_eigs(T: np.ndarray) -> np.ndarray:
    """Eigenvalues of a real Schur factor (1x1 and standardised 2x2 diagonal blocks),
    read off the blocks instead of recomputed from scratch."""
    m = T.shape[0]
    ev = np.empty(m, complex)
    i = 0
    while i < m:
        if i + 1 < m and T[i + 1, i] != 0.0:
            a, b, c, d = T[i, i], T[i, i + 1], T[i + 1, i], T[i + 1, i + 1]
            h = 0.5 * (a + d)
            s = np.sqrt(complex((0.5 * (a - d)) ** 2 + b * c))
            ev[i], ev[i + 1] = h + s, h - s
            i += 2
        else:
            ev[i] = T[i, i]
            i += 1
    return ev


def _ric(H: np.ndarray):
    """Stabilizing solution X of the Riccati equation with Hamiltonian H.

    Returns ``(X, "")``, or ``(None, why)`` if H has eigenvalues on (or within
    rounding of) the imaginary axis or its stable subspace is not a graph."""
    n = H.shape[0] // 2
    if not np.all(np.isfinite(H)):
        return None, "the Hamiltonian has non-finite entries"
    try:
        T, Z, sdim = sla.schur(H, output="real", sort="lhp")
    except (np.linalg.LinAlgError, ValueError):  # reordering failed: eigenvalues too close to split
        return None, "the Schur reordering failed (eigenvalues too close to the imaginary axis to separate)"
    ev = _quasi_eigs(T)
    # H is Hamiltonian: its eigenvalues come in pairs (lam, -conj(lam)); one within
    # 1e-10 of the spectral radius from the axis cannot be assigned to either half
    near = np.abs(ev.real) < 1e-10 * max(1.0, float(np.abs(ev).max()))
    if np.any(near) or sdim != n:
        k = int(np.argmin(np.abs(ev.real)))
        return None, f"the Hamiltonian has an eigenvalue on the imaginary axis ({ev[k]:.3g})"
    U1, U2 = Z[:n, :n], Z[n:, :n]
    c = np.linalg.cond(U1)
    if not c < 1e13:
        return None, f"the stable invariant subspace is not a graph (cond U1 = {c:.2g})"
    X = np.linalg.solve(U1.T, U2.T).T
    return _sym(X), ""


def _riccati_solutions(p: PlantParts, g: float):
    """``(X_inf, Y_inf, "")`` at level ``g`` if the four conditions of ZDG Theorem 17.1
    hold, else ``(None, None, why)``; see :func:`riccati_feasible`."""
    n, nw, nu, nz, ny = p.sizes
    A, B1, B2, C1, C2, D11, D12, D21 = p.A, p.B1, p.B2, p.C1, p.C2, p.D11, p.D12, p.D21
    P12 = D12 @ np.linalg.pinv(D12)
    P21 = np.linalg.pinv(D21) @ D21
    d = max(np.linalg.norm((np.eye(nz) - P12) @ D11, 2), np.linalg.norm(D11 @ (np.eye(nw) - P21), 2))
    if d >= g:
        return None, None, f"the part of D11 that neither u nor y reaches has gain {d:.6g} >= {g:.6g}"
    B = np.hstack([B1, B2])
    D1 = np.hstack([D11, D12])
    R = D1.T @ D1 - sla.block_diag(g * g * np.eye(nw), np.zeros((nu, nu)))
    Hx = (np.block([[A, np.zeros((n, n))], [-C1.T @ C1, -A.T]])
          - np.vstack([B, -C1.T @ D1]) @ np.linalg.solve(R, np.hstack([D1.T @ C1, B.T])))
    X, why = _ric(Hx)
    if X is None:
        return None, None, "X_inf: " + why
    C = np.vstack([C1, C2])
    Dc = np.vstack([D11, D21])
    Rt = Dc @ Dc.T - sla.block_diag(g * g * np.eye(nz), np.zeros((ny, ny)))
    Jy = (np.block([[A.T, np.zeros((n, n))], [-B1 @ B1.T, -A]])
          - np.vstack([C.T, -B1 @ Dc.T]) @ np.linalg.solve(Rt, np.hstack([Dc @ B1.T, C])))
    Y, why = _ric(Jy)
    if Y is None:
        return None, None, "Y_inf: " + why
    tol = 1e-10
    for name, M in (("X_inf", X), ("Y_inf", Y)):
        e = float(np.linalg.eigvalsh(M).min())
        if e < -tol * max(1.0, np.abs(M).max()):
            return None, None, f"{name} is not positive semidefinite (eigenvalue {e:.3g})"
    rho = float(np.max(np.abs(np.linalg.eigvals(X @ Y))))
    if not rho < g * g:
        return None, None, f"rho(X_inf Y_inf) = {rho:.6g} >= gamma^2 = {g * g:.6g}"
    return X, Y, ""


def riccati_feasible(p: PlantParts, g: float) -> bool:
    r"""Exact test of whether a controller with closed-loop norm < g exists, for
    regular problems (``D12`` full column rank, ``D21`` full row rank).

    The conditions of Zhou, Doyle and Glover, *Robust and Optimal Control*,
    Theorem 17.1 (general case, no normalisation of ``D12``, ``D21``): with
    :math:`R = D_{1\bullet}^TD_{1\bullet} - \mathrm{diag}(g^2I, 0)`,
    :math:`\tilde R = D_{\bullet1}D_{\bullet1}^T - \mathrm{diag}(g^2I, 0)`,
    (i) ``g`` exceeds the gain of the parts of ``D11`` that neither ``u`` nor
    ``y`` can reach; (ii) the Hamiltonian :math:`H_\infty` has a stabilizing
    Riccati solution :math:`X_\infty \succeq 0`; (iii) likewise
    :math:`Y_\infty \succeq 0` for :math:`J_\infty`; (iv)
    :math:`\rho(X_\infty Y_\infty) < g^2`.
    """
    return _riccati_solutions(p, g)[2] == ""


def _normalise_d12_d21(p: PlantParts):
    r"""The plant with :math:`D_{12} = [0;\ I]` and :math:`D_{21} = [0\ \ I]`.

    ``z`` and ``w`` are rotated (orthogonal, so every closed-loop norm is
    unchanged) and ``u``, ``y`` transformed invertibly: ``u = Tu u_n``,
    ``y_n = Ty y``.  A controller ``K_n`` of the normalised plant is
    ``K = Tu K_n Ty`` for the original.  Raises :class:`IllPosedError` if
    ``D12`` or ``D21`` is rank deficient (singular problem)."""
    _, nw, nu, nz, ny = p.sizes
    U, s, Vt = np.linalg.svd(p.D12)
    U2, s2, Vt2 = np.linalg.svd(p.D21)
    for name, sv, r in (("D12", s, nu), ("D21", s2, ny)):
        if sv.size < r or not sv[-1] > 1e-13 * max(sv[0], 1e-300):
            raise IllPosedError(f"{name} is rank deficient (singular values {np.array2string(sv, precision=3)}): "
                                "the central controller needs D12 full column rank and D21 full row rank")
    Uz = np.hstack([U[:, nu:], U[:, :nu]])            # range of D12 last
    Tu = Vt.T / s[None, :]
    Ww = np.vstack([Vt2[ny:], Vt2[:ny]]).T             # row space of D21 last
    Ty = (U2 / s2[None, :]).T
    D12 = np.vstack([np.zeros((nz - nu, nu)), np.eye(nu)])
    D21 = np.hstack([np.zeros((ny, nw - ny)), np.eye(ny)])
    q = PlantParts(p.A, p.B1 @ Ww, p.B2 @ Tu, Uz.T @ p.C1, Ty @ p.C2, Uz.T @ p.D11 @ Ww, D12, D21,
                   Ty @ p.D22 @ Tu)
    return q, Tu, Ty


def central_controller(p: PlantParts, g: float):
    r"""The central H-infinity controller at level ``g`` from the Riccati solutions.

    Glover and Doyle's formulas for the general case (Zhou, Doyle and Glover
    [ZDG]_ ch. 17, with the normalisation of ``D12`` and ``D21``), written here
    for a plant with :math:`D_{12} = [0;\ I]`, :math:`D_{21} = [0\ \ I]`
    (any regular plant is brought to this form by :func:`_normalise_d12_d21`:
    orthogonal changes of ``z`` and ``w``, invertible ones of ``u`` and ``y``)
    and :math:`D_{22} = 0` (added back at the end, below).  With
    :math:`D_{1\bullet} = [D_{11}\ D_{12}]`, :math:`D_{\bullet1} = [D_{11};\ D_{21}]`,
    :math:`B = [B_1\ B_2]`, :math:`C = [C_1;\ C_2]`, the stabilizing
    solutions :math:`X_\infty, Y_\infty \succeq 0` of :math:`H_\infty, J_\infty`
    (:func:`riccati_feasible`) and

    .. math::
        F = \begin{bmatrix} F_{11}\\ F_{12}\\ F_2\end{bmatrix}
          = -R^{-1}\bigl(D_{1\bullet}^TC_1 + B^TX_\infty\bigr),\qquad
        L = [L_{11}\ L_{12}\ L_2] = -\bigl(B_1D_{\bullet1}^T + Y_\infty C^T\bigr)\tilde R^{-1},

    partitioned like :math:`w = (w_1, w_2)`, ``u`` and :math:`z = (z_1, z_2)`,
    ``y`` (:math:`w_2` and :math:`z_2` the channels that ``y`` and ``u``
    reach, so :math:`D_{11} = [D_{1111}\ D_{1112};\ D_{1121}\ D_{1122}]`), the
    central controller is :math:`K = (\hat A, \hat B_1, \hat C_1, \hat D_{11})` with

    .. math::
        \hat D_{11} &= -D_{1121}D_{1111}^T(g^2I - D_{1111}D_{1111}^T)^{-1}D_{1112} - D_{1122},\\
        \hat D_{12}\hat D_{12}^T &= I - D_{1121}(g^2I - D_{1111}^TD_{1111})^{-1}D_{1121}^T,\quad
        \hat D_{21}^T\hat D_{21} = I - D_{1112}^T(g^2I - D_{1111}D_{1111}^T)^{-1}D_{1112},\\
        Z_\infty &= (I - g^{-2}Y_\infty X_\infty)^{-1},\quad
        \hat B_2 = Z_\infty(B_2 + L_{12})\hat D_{12},\quad \hat C_2 = -\hat D_{21}(C_2 + F_{12}),\\
        \hat B_1 &= -Z_\infty L_2 + \hat B_2\hat D_{12}^{-1}\hat D_{11},\quad
        \hat C_1 = F_2 + \hat D_{11}\hat D_{21}^{-1}\hat C_2,\quad
        \hat A = A + BF + \hat B_1\hat D_{21}^{-1}\hat C_2 .

    :math:`\hat B_2, \hat C_2, \hat D_{12}, \hat D_{21}` parametrise the other
    suboptimal controllers; in the central one they cancel,
    :math:`\hat B_1 = Z_\infty\bigl((B_2 + L_{12})\hat D_{11} - L_2\bigr)`,
    :math:`\hat C_1 = F_2 - \hat D_{11}(C_2 + F_{12})`, and only the existence of
    :math:`\hat D_{12}, \hat D_{21}` (``g`` above the gains of the ``D11`` blocks)
    is checked.  The realisation is formed in descriptor form,
    :math:`Z_\infty^{-1}\dot x_K = \dots`, and :math:`Z_\infty^{-1}` inverted once
    through its SVD (see the comment in the code for why).  With
    :math:`D_{22} \ne 0` the controller is :math:`K(I + D_{22}K)^{-1}`.

    Parameters
    ----------
    p : PlantParts
        Regular plant (``D12`` full column rank, ``D21`` full row rank).
    g : float
        Level, strictly above the optimal one.

    Returns
    -------
    Ak, Bk, Ck, Dk : ndarray
        The controller ``u = K y`` (same order as the plant).
    info : dict
        ``cond_Z`` (conditioning of :math:`I - g^{-2}Y_\infty X_\infty`, which
        grows as ``g`` nears the optimum) and the largest entries of
        :math:`X_\infty`, :math:`Y_\infty`.

    Raises
    ------
    InfeasibleError
        The Riccati conditions fail at ``g`` (the reason is named).
    IllPosedError
        ``D12`` or ``D21`` rank deficient, or ``I + D22 Dk`` singular.

    References
    ----------
    K. Glover and J. C. Doyle, "State-space formulae for all stabilizing
    controllers that satisfy an H-infinity norm bound and relations to risk
    sensitivity", *Systems & Control Letters* 11 (1988) 167-172; [ZDG]_ ch. 16-17.
    """
    q, Tu, Ty = _normalise_d12_d21(p)
    n, nw, nu, nz, ny = q.sizes
    X, Y, why = _riccati_solutions(q, g)
    if X is None:
        raise InfeasibleError(f"central controller at gamma={g:.6g}: Riccati conditions fail ({why})")
    A, B1, B2, C1, C2, D11 = q.A, q.B1, q.B2, q.C1, q.C2, q.D11
    B, C = np.hstack([B1, B2]), np.vstack([C1, C2])
    D1, Dc = np.hstack([D11, q.D12]), np.vstack([D11, q.D21])
    g2 = g * g
    R = D1.T @ D1 - sla.block_diag(g2 * np.eye(nw), np.zeros((nu, nu)))
    Rt = Dc @ Dc.T - sla.block_diag(g2 * np.eye(nz), np.zeros((ny, ny)))
    F = -np.linalg.solve(R, D1.T @ C1 + B.T @ X)
    L = -np.linalg.solve(Rt.T, (B1 @ Dc.T + Y @ C.T).T).T
    m1, p1 = nw - ny, nz - nu
    F12, F2 = F[m1:nw], F[nw:]
    L12, L2 = L[:, p1:nz], L[:, nz:]
    D1111, D1112, D1121, D1122 = D11[:p1, :m1], D11[:p1, m1:], D11[p1:, :m1], D11[p1:, m1:]
    if p1 and m1:
        Dh11 = -D1121 @ D1111.T @ np.linalg.solve(g2 * np.eye(p1) - D1111 @ D1111.T, D1112) - D1122
        M12 = np.eye(nu) - D1121 @ np.linalg.solve(g2 * np.eye(m1) - D1111.T @ D1111, D1121.T)
        M21 = np.eye(ny) - D1112.T @ np.linalg.solve(g2 * np.eye(p1) - D1111 @ D1111.T, D1112)
    else:  # z = z2 or w = w2: the D1111 terms are absent
        Dh11 = -D1122
        M12 = np.eye(nu) - D1121 @ D1121.T / g2
        M21 = np.eye(ny) - D1112.T @ D1112 / g2
    # Dh12, Dh21 (Cholesky factors of M12, M21) cancel from the central controller's
    # realisation below; only their existence is needed
    try:
        np.linalg.cholesky(_sym(M12))
        np.linalg.cholesky(_sym(M21))
    except np.linalg.LinAlgError:
        raise InfeasibleError(f"central controller at gamma={g:.6g}: gamma is below the gain of the "
                              "D11 blocks the controller can act on") from None
    # Descriptor form: multiplying the controller's state equation by
    # E = I - Y X / g^2 = Z_inf^-1 removes the inverse of E from every product,
    #   E xk' = (E (A + B F) + Bb Dh21^-1 Ch2) xk + Bb y,  u = Ch1 xk + Dh11 y,
    # with Bb = (B2 + L12) Dh11 - L2 (so that Bh1 = Z_inf Bb); E is then inverted
    # once, through its SVD E = U diag(s) V^T, in the coordinates xk = V xt.
    # Near the optimum E is nearly singular; forming Z_inf first and multiplying
    # it into B and A (the textbook order) gave controllers whose closed-loop norm
    # moved by up to 50 % under relative perturbations of 1e-13 of their entries
    # (random plant 2: 1.5 % above the target at back-off 1e-4; 1e-8 in this form).
    E = np.eye(n) - (Y @ X) / g2
    Bb = (B2 + L12) @ Dh11 - L2
    G = -(C2 + F12)                                      # Dh21^-1 Ch2
    Ch1 = F2 + Dh11 @ G
    Ad = E @ (A + B @ F) + Bb @ G
    U, sE, Vt = np.linalg.svd(E)
    condZ = float(sE[0] / sE[-1]) if sE[-1] > 0 else np.inf
    if not condZ < 1e14:
        raise InfeasibleError(f"central controller at gamma={g:.6g}: I - Y_inf X_inf / gamma^2 is singular "
                              f"(cond {condZ:.2g}); gamma is at the coupling limit rho(X_inf Y_inf) = gamma^2")
    Ak = (U.T @ Ad @ Vt.T) / sE[:, None]
    Bh1 = (U.T @ Bb) / sE[:, None]
    Ch1 = Ch1 @ Vt.T
    # back to the plant's own u and y: u = Tu u_n, y_n = Ty y
    Bk, Ck, Dk = Bh1 @ Ty, Tu @ Ch1, Tu @ Dh11 @ Ty
    Ak, Bk, Ck, Dk = _add_d22(Ak, Bk, Ck, Dk, p.D22)
    info = {"cond_Z": condZ, "max_X": float(np.abs(X).max(initial=0.0)),
            "max_Y": float(np.abs(Y).max(initial=0.0))}
    return Ak, Bk, Ck, Dk, info


def _riccati_level(p: PlantParts, rtol: float = 1e-10, max_steps: int = 200):
    """Optimal level of a regular plant by bisection on :func:`riccati_feasible`
    (the gamma iteration of the Riccati method; geometric bisection).

    Returns ``(gamma, steps)``: ``gamma`` is a level where the Riccati
    conditions hold and ``gamma (1 - rtol)`` one where they fail; or ``None``
    if no feasible level is found (numerical trouble: the LMIs take over)."""
    q, _, _ = _normalise_d12_d21(p)
    _, nw, nu, nz, ny = q.sizes
    m1, p1 = nw - ny, nz - nu
    # condition (i): below the gain of [D1111 D1112] and [D1111; D1121] nothing is feasible
    lo = max(np.linalg.norm(q.D11[:p1], 2) if p1 else 0.0, np.linalg.norm(q.D11[:, :m1], 2) if m1 else 0.0)
    steps = 0
    hi = max(2.0 * lo, 1.0)
    while not riccati_feasible(q, hi):
        steps += 1
        lo, hi = hi, 4.0 * hi
        if steps > 40 or not np.isfinite(hi):
            return None
    if lo == 0.0:
        lo = hi
        while riccati_feasible(q, lo):
            steps += 1
            hi, lo = lo, 0.25 * lo
            if steps > 80:
                return hi, steps      # the level is 0 to double precision
    while hi > lo * (1.0 + rtol) and steps < max_steps:
        steps += 1
        mid = np.sqrt(lo * hi)
        if riccati_feasible(q, mid):
            hi = mid
        else:
            lo = mid
    return hi, steps


def _regularised(p: PlantParts, eps: float) -> PlantParts:
    """The plant with ``eps * u`` appended to ``z`` and ``eps * v`` (a new disturbance)
    added to ``y``: ``D12 = [D12; eps I]`` and ``D21 = [D21, eps I]`` have full rank.
    ``w -> z`` of the original is a sub-block of the regularised closed loop, so a
    controller achieving ``g`` on it achieves ``g`` on ``p``."""
    n, _, nu, _, ny = p.sizes
    return PlantParts(p.A, np.hstack([p.B1, np.zeros((n, ny))]), p.B2,
                      np.vstack([p.C1, np.zeros((nu, n))]), p.C2,
                      sla.block_diag(p.D11, np.zeros((nu, ny))), np.vstack([p.D12, eps * np.eye(nu)]),
                      np.hstack([p.D21, eps * np.eye(ny)]), p.D22)


def _near_axis_hint(P, ratio: float = 1e-6) -> str:
    """A note for failure messages when the plant has stable poles so slow, against
    its fastest ones, that an LMI solver cannot resolve them (typically an integrator
    in a performance weight approximated by a pole at 1e-6)."""
    A = np.asarray(P.A, float)
    if A.size == 0:
        return ""
    lam = np.linalg.eigvals(A)
    fast = float(np.abs(lam).max())
    slow = lam[(lam.real < 0) & (np.abs(lam.real) < ratio * fast)]
    if fast == 0 or slow.size == 0:
        return ""
    worst = float(np.abs(slow.real).min())
    return (f" [the plant has {slow.size} stable pole(s) with real part down to {-worst:.3g} against modes up to "
            f"{fast:.3g} rad/s (ratio {worst / fast:.1g}): the LMIs cannot resolve them in double precision; "
            f"moving them to at least {ratio * 10 * fast:.2g} rad/s (e.g. a weight's integrator "
            f"approximation) usually fixes this]")


def _refine_level(p: PlantParts, g_lmi: float, rtol: float = 1e-10):
    """Bisection on :func:`riccati_feasible` around the LMI level.  Returns the
    refined level, or None if the test does not bracket the LMI level."""
    hi = g_lmi * (1 + 1e-3)
    for _ in range(8):
        if riccati_feasible(p, hi):
            break
        hi *= 1.5
    else:
        return None
    lo = g_lmi * (1 - 1e-2)
    for _ in range(8):
        if not riccati_feasible(p, lo):
            break
        lo *= 0.5
    else:
        return None
    while hi - lo > rtol * hi:
        mid = 0.5 * (lo + hi)
        if riccati_feasible(p, mid):
            hi = mid
        else:
            lo = mid
    return hi


def _add_d22(Ak, Bk, Ck, Dk, D22):
    """Controller for the plant with feedthrough D22 from K0 designed with D22 = 0:
    K = K0 (I + D22 K0)^{-1}."""
    if not np.any(D22):
        return Ak, Bk, Ck, Dk
    E = np.eye(Dk.shape[0]) + Dk @ D22
    if np.linalg.cond(E) > 1e12:
        raise IllPosedError("I + DK*D22 is singular: the controller loop is not well posed with this D22")
    Z = np.linalg.inv(E)
    return (Ak - Bk @ D22 @ Z @ Ck, Bk @ (np.eye(D22.shape[0]) - D22 @ Z @ Dk), Z @ Ck, Z @ Dk)


# ----------------------------------------------------------------------------
# verification
# ----------------------------------------------------------------------------

def slycot_hinf_norm(sys) -> float:
    """H-infinity norm by SLICOT AB13DD (through slycot), used as an independent check.

    AB13DD is asked to equilibrate the system first (``EQUIL='S'``, as
    python-control's ``linfnorm`` does): without it, on the flat closed loops of
    near-optimal controllers of badly scaled plants, it overestimated the norm
    by up to 1.3e-3 relative, where a direct complex solve at its own peak
    frequency agreed with our value to 1e-7.  Returns ``nan`` when slycot is not
    available or fails.
    """
    sys = as_ss(sys)
    try:
        from slycot import ab13dd
    except ImportError:  # pragma: no cover - slycot is a dependency
        return float("nan")
    n, m, p = sys.nstates, sys.ninputs, sys.noutputs
    if n == 0:
        return float(np.linalg.norm(np.asarray(sys.D, float), 2))
    try:
        gpeak, _ = ab13dd('C', 'I', 'S', 'D', n, m, p, np.asarray(sys.A, float), np.eye(n),
                          np.asarray(sys.B, float), np.asarray(sys.C, float),
                          np.asarray(sys.D, float))
    except Exception:  # slycot raises several error types; the check is advisory
        return float("nan")
    return float(gpeak)


@dataclass
class SlycotReference:
    """What slycot's Riccati ``hinfsyn`` returned for a plant, and whether it holds up.

    ``status`` is ``'verified'`` (its controller stabilises the rebuilt closed
    loop and achieves the claimed level to ``rtol``), ``'unverified'`` (it
    returned, but the claim does not hold: see ``note``), ``'error'`` (it
    refused the problem) or ``'timeout'``.
    """
    status: str
    gamma: float = float("nan")
    K: ct.StateSpace | None = None
    achieved: float = float("nan")
    note: str = ""
    seconds: float = 0.0


def _slycot_child(P, nmeas, ncon, conn, cpu_seconds=None):
    if cpu_seconds is not None:
        import resource
        soft = max(1, int(np.ceil(cpu_seconds)))
        # SIGXCPU at the soft limit, SIGKILL one second of CPU later
        resource.setrlimit(resource.RLIMIT_CPU, (soft, soft + 1))
    try:
        t0 = time.perf_counter()
        K, _, gam, _ = ct.hinfsyn(P, nmeas, ncon)
        conn.send(("ok", float(gam), (K.A, K.B, K.C, K.D), time.perf_counter() - t0))
    except Exception as exc:  # slycot raises several error types; each is a result to report
        conn.send(("error", f"{type(exc).__name__}: {str(exc).splitlines()[0][:80] if str(exc) else ''}",
                   None, 0.0))
    conn.close()


def slycot_hinfsyn(P, nmeas: int, ncon: int, timeout: float | None = 20.0,
                   rtol: float = 1e-3) -> SlycotReference:
    """Run python-control/slycot's ``hinfsyn`` as an independent reference, and check its claim.

    slycot (SB10AD) can take very long or never return on badly scaled or
    singular plants, so with ``timeout`` set it runs in a forked child process
    that is stopped once it has used ``timeout`` seconds of CPU time (the
    operating system's CPU-time limit, so the outcome does not depend on how
    busy the machine is; a child that waits without computing is stopped
    after ``10 * timeout + 60`` seconds of wall-clock time).  Its controller is
    then checked the same way ours is: closed loop rebuilt from ``P`` and
    ``K``, stability, norm recomputed by :func:`mutext.lti.hinf_norm`.
    """
    import multiprocessing as mp
    P = as_ss(P, "P")
    t0 = time.perf_counter()
    if timeout is None:
        parent, child = mp.Pipe(duplex=False)
        _slycot_child(P, nmeas, ncon, child)
        msg = parent.recv()
    else:
        parent, child = mp.Pipe(duplex=False)
        import signal
        proc = mp.get_context("fork").Process(target=_slycot_child, args=(P, nmeas, ncon, child, timeout))
        with warnings.catch_warnings():  # fork from a threaded process: the child only runs slycot
            warnings.simplefilter("ignore", DeprecationWarning)
            proc.start()
        child.close()
        if not parent.poll(10 * timeout + 60):
            proc.kill()
            proc.join()
            return SlycotReference("timeout", note=f"no answer within {10 * timeout + 60:g} s (idle child)",
                                   seconds=time.perf_counter() - t0)
        try:
            msg = parent.recv()
        except EOFError:
            proc.join()
            if proc.exitcode in (-signal.SIGXCPU, -signal.SIGKILL):
                return SlycotReference("timeout", note=f"no answer within {timeout:g} s of CPU time",
                                       seconds=time.perf_counter() - t0)
            msg = ("error", f"slycot process died (exit code {proc.exitcode})", None, 0.0)
        proc.join()
    status, gam, mats, sec = msg
    if status == "error":
        return SlycotReference("error", note=gam, seconds=sec)
    K = ss(*mats)
    CL = lft_lower(P, K, nmeas, ncon)
    stab = stability(CL)
    if not stab.stable:
        return SlycotReference("unverified", gam, K, np.inf, f"its closed loop is {stab.message}", sec)
    with warnings.catch_warnings():  # slycot's controllers often have poles near 1e10 rad/s
        warnings.simplefilter("ignore", sla.LinAlgWarning)
        achieved = hinf_norm(CL).value
    if abs(achieved - gam) > rtol * gam:
        return SlycotReference("unverified", gam, K, achieved,
                               f"claims {gam:.7g}, its controller achieves {achieved:.7g}", sec)
    return SlycotReference("verified", gam, K, achieved, "", sec)


@dataclass
class HinfResult:
    r"""Result of :func:`hinfsyn`.

    Attributes
    ----------
    K : control.StateSpace
        The controller (``ncon`` outputs, ``nmeas`` inputs).
    CL : control.StateSpace
        The closed loop :math:`\mathcal F_\ell(P, K)` rebuilt from ``P`` and ``K``.
    gamma : float
        Optimal level (Riccati gamma iteration or LMIs, see ``info["level_method"]``):
        the infimum of the closed-loop norm over all stabilizing controllers (to
        the accuracy of that computation).
    gamma_target : float
        The level at which the controller was constructed (``gamma`` times
        ``1 + backoff``).
    closed_loop_norm : float
        :math:`\|\mathcal F_\ell(P, K)\|_\infty` recomputed by our Hamiltonian algorithm.
    closed_loop_norm_slycot : float
        The same norm by SLICOT AB13DD (``nan`` if unavailable).
    closed_loop_norm_grid : float
        Peak of the largest singular value on a log-spaced frequency grid (a lower bound).
    peak_frequency : float
        Frequency (rad/s) of the closed-loop peak.
    stable : bool
        All closed-loop poles in the open left half plane.
    controller_poles : ndarray
    notes : list of str
        Properties of the problem worth knowing (singular D12/D21, D22 handling, ...).
    info : dict
        ``level_method`` (how ``gamma`` was found), ``tries`` (every controller
        built, with its verification), ``stability`` (the verdict on the closed
        loop, naming the deciding pole), scalings.
    construction : str
        How ``K`` was built: the central controller from the Riccati solutions
        (:func:`central_controller`) or the LMI reconstruction.
    """
    K: ct.StateSpace
    CL: ct.StateSpace
    gamma: float
    gamma_target: float
    closed_loop_norm: float
    closed_loop_norm_slycot: float
    closed_loop_norm_grid: float
    peak_frequency: float
    stable: bool
    max_closed_loop_real_part: float
    controller_poles: np.ndarray
    backoff: float
    notes: list = field(default_factory=list)
    solver: str = "CLARABEL"
    seconds: float = 0.0
    info: dict = field(default_factory=dict)
    construction: str = ""

    def __post_init__(self):
        # plain floats: numpy scalars print as np.float64(...) in reports and doctests
        for name in ("gamma", "gamma_target", "closed_loop_norm", "closed_loop_norm_slycot",
                     "closed_loop_norm_grid", "peak_frequency", "max_closed_loop_real_part", "backoff"):
            setattr(self, name, float(getattr(self, name)))
        self.stable = bool(self.stable)

    @property
    def controller_order(self) -> int:
        return self.K.nstates

    @property
    def controller_rhp_poles(self) -> np.ndarray:
        return self.controller_poles[self.controller_poles.real > 0]

    def summary(self) -> str:
        """A short human-readable report."""
        lines = [
            f"optimal level             gamma = {self.gamma:.6f} ({self.info.get('level_method', 'LMI')})",
            (f"controller built at       gamma = {self.gamma_target:.6f} (backoff {self.backoff:g}; "
             f"{self.construction or 'LMI'})"),
            f"closed-loop norm (ours)         = {self.closed_loop_norm:.6f} at {self.peak_frequency:.4g} rad/s",
            f"closed-loop norm (slycot AB13DD)= {self.closed_loop_norm_slycot:.6f}",
            f"closed loop stable              = {self.stable} (max real part {self.max_closed_loop_real_part:.3g})",
            f"controller order                = {self.controller_order}, "
            f"right-half-plane poles: {len(self.controller_rhp_poles)}",
        ]
        lines += [f"note: {n}" for n in self.notes]
        return "\n".join(lines)


def _verify(P, K, nmeas, ncon):
    """Rebuild the closed loop from ``P`` and ``K``; decide stability by the
    scale-aware rule of :func:`mutext.lti.stability` (each pole against its own
    magnitude and the balanced ``A``, not the raw sign of its real part) and
    recompute the norm three ways.  Returns ``(CL, stable, max real part, norm,
    peak frequency, AB13DD norm, grid peak, Stability report)``."""
    CL = lft_lower(P, K, nmeas, ncon)
    stab = stability(CL)
    poles = stab.poles
    maxre = stab.max_real_part
    stable = stab.stable
    if stable:
        nrm = hinf_norm(CL)
        value, wpk = nrm.value, nrm.frequency
    else:
        value, wpk = np.inf, np.nan
    sly = slycot_hinf_norm(CL) if stable else np.inf
    # grid: log-spaced around the pole magnitudes, plus the peak found
    if CL.nstates:
        mags = np.abs(poles[np.abs(poles) > 0]) if poles.size else np.array([1.0])
        lo, hi = (mags.min() / 100, mags.max() * 100) if mags.size else (1e-3, 1e3)
    else:
        lo, hi = 1e-3, 1e3
    grid = np.logspace(np.log10(lo), np.log10(hi), 400)
    if np.isfinite(wpk) and wpk > 0:
        grid = np.sort(np.append(grid, wpk))
    gpk = float(sigma_max(CL, grid).max()) if stable else np.inf
    gpk = max(gpk, float(np.linalg.norm(np.asarray(CL.D, float), 2)) if CL.D.size else 0.0)
    return CL, stable, maxre, value, wpk, sly, gpk, stab


@dataclass
class _Level:
    """Optimal level and the working coordinates it was computed in."""
    work: PlantParts       # scaled plant with D22 = 0 (level = gamma / gscale)
    D22: np.ndarray        # D22 of the scaled plant
    gscale: float
    gamma: float           # true optimal level
    gamma_lmi: float
    R: np.ndarray
    S: np.ndarray
    status: str
    levels: list
    method: str
    su: np.ndarray
    sy: np.ndarray
    tstate: np.ndarray
    alpha: float = 1.0  # time scaling, P_work(s) = P(alpha s)


def _time_scale(p: PlantParts, alpha: float) -> PlantParts:
    """The plant with frequency axis rescaled, P'(s) = P(alpha s); the H-infinity
    level is unchanged and a controller K' for P' gives K(s) = K'(s / alpha)."""
    r = 1.0 / np.sqrt(alpha)
    return PlantParts(p.A / alpha, r * p.B1, r * p.B2, r * p.C1, r * p.C2, p.D11, p.D12, p.D21, p.D22)


def _level(parts: PlantParts, notes: list, solver: str, scale: bool, refine: bool) -> _Level:
    nmeas, ncon = parts.C2.shape[0], parts.B2.shape[1]
    if scale:
        work, su, sy, tstate, alpha, c0 = _scale(parts)
    else:
        work, su, sy, tstate, alpha, c0 = parts, np.ones(ncon), np.ones(nmeas), np.ones(parts.n), 1.0, 1.0
    D22 = work.D22
    work0 = PlantParts(work.A, work.B1, work.B2, work.C1, work.C2, work.D11, work.D12, work.D21,
                       np.zeros_like(D22))
    # Pass 0 locates the level.  If the solver gives up, retry with w and z
    # scaled down (large levels make the gamma blocks dominate the LMIs).
    gscale, first, errors = c0, None, []
    for c in (1.0, 1e3, 1e6):
        trial = _transform(work0, np.eye(parts.n), c) if c != 1.0 else work0
        for tight in (False, True):
            try:
                first = _optimal_level(trial, solver, tight=tight)
                break
            except SolverError as exc:
                errors.append(str(exc))
            except InfeasibleError as exc:
                errors.append(str(exc))
                break
            except (ValueError, np.linalg.LinAlgError) as exc:   # NaN in the problem data
                errors.append(f"H-infinity optimal level: {exc}")
                break
        if first is not None:
            work0, gscale = trial, c0 * c
            break
    if first is None:
        raise SolverError(f"H-infinity optimal level: the LMI solver failed on the scaled plant{_near_axis_hint(parts)} "
                          f"(tried w, z scalings 1, 1e3, 1e6); last error: {errors[-1]}")
    g0, R, S, st1 = first
    if not np.isfinite(g0) or g0 < 1e-8:
        # the level of the normalised plant (w -> z gain of order one) is zero to
        # the solver's accuracy: a singular problem whose infimum 0 is approached
        # only by controllers of unbounded gain (e.g. an integrator with full
        # control and measurement, z = x); there is no controller to return
        raise IllPosedError(
            f"H-infinity optimal level: the infimum of the closed-loop norm is 0 to solver accuracy "
            f"(level {g0 * gscale:.3g} against a w -> z gain of about {gscale:.3g}); it is approached only by "
            "controllers of unbounded gain and not attained (a singular problem: D12 or D21 rank deficient "
            "without a penalty on u or noise on y). Add a control penalty in z or sensor noise in y.")
    # Later passes re-solve in the state coordinates that balance the previous
    # solution (R, S) and with w, z scaled so that the level is near 1.
    # Plant-based balancing alone leaves R and S spread over decades, which
    # costs the solver digits.  A pass that raises the level is discarded.
    gamma = g0 * gscale
    levels = [gamma]
    best = (gamma, work0, gscale, R, S, st1)
    for _ in range(3):
        T = _balancing_transform(R, S)
        if T is None or not np.all(np.isfinite(T)):
            T = np.eye(parts.n)
        c = gamma / gscale
        trial = _transform(work0, T, c)
        if not all(np.all(np.isfinite(X)) for X in (trial.A, trial.B1, trial.B2, trial.C1, trial.C2, trial.D11,
                                                      trial.D12, trial.D21)):
            break
        try:
            g2, R2, S2, st2 = _optimal_level(trial, solver, tight=True)
        except (InfeasibleError, SolverError, ValueError, np.linalg.LinAlgError):
            break
        g2 *= gscale * c
        levels.append(g2)
        if st2 != cp.OPTIMAL:
            break
        work0, R, S, st1, gscale = trial, R2, S2, st2, gscale * c
        converged = abs(g2 - gamma) <= 1e-9 * gamma
        if g2 > best[0] * (1 + 1e-7):
            break
        gamma = g2
        best = (gamma, work0, gscale, R, S, st1)
        if converged:
            break
    gamma, work0, gscale, R, S, st1 = best
    if not np.isfinite(gamma) or gamma <= 0:
        raise SolverError(f"H-infinity optimal level: solver returned gamma={gamma}")
    gamma_lmi = gamma
    level_method = "LMI"
    if st1 != cp.OPTIMAL:
        level_method = f"LMI (solver status {st1})"
    regular = not any(n.startswith(("D12 does not", "D21 does not", "[A - jwI")) for n in notes)
    if regular and refine:
        g_ref = _refine_level(work0, gamma / gscale)
        if g_ref is not None and g_ref * gscale <= gamma * (1 + 1e-3):
            gamma = g_ref * gscale
            level_method += ", refined by bisection on the Riccati conditions"
            if gamma < gamma_lmi * (1 - 1e-4):
                notes.append(f"the LMI solver's level {gamma_lmi:.6g} was inaccurate; the Riccati "
                             f"conditions (ZDG Thm 17.1) place the optimum at {gamma:.6g}")
    return _Level(work0, D22, gscale, gamma, gamma_lmi, R, S, st1, levels, level_method, su, sy,
                  tstate, alpha)

CENTRAL = "central (Glover-Doyle formulas from the Riccati solutions)"
LMI_CONTROLLER = "LMI (Scherer-Gahinet-Chilali reconstruction)"
CENTRAL_REGULARISED = "central of the regularised plant (Glover-Doyle formulas, eps * u added to z, eps * v to y)"


def _working_plant(parts: PlantParts, scale: bool) -> _Level:
    """The scaled plant with ``D22`` set aside (a :class:`_Level` without a level yet)."""
    nmeas, ncon = parts.C2.shape[0], parts.B2.shape[1]
    if scale:
        work, su, sy, tstate, alpha, c0 = _scale(parts)
    else:
        work, su, sy, tstate, alpha, c0 = parts, np.ones(ncon), np.ones(nmeas), np.ones(parts.n), 1.0, 1.0
    work0 = PlantParts(work.A, work.B1, work.B2, work.C1, work.C2, work.D11, work.D12, work.D21,
                       np.zeros_like(work.D22))
    return _Level(work0, work.D22, c0, float("nan"), float("nan"), None, None, "", [], "", su, sy, tstate, alpha)


def _well_conditioned_d(parts: PlantParts, scale: bool, tol: float = 1e-8) -> bool:
    """``D12`` and ``D21`` of the working plant (``u`` and ``y`` channels normalised)
    have smallest singular values above ``tol``."""
    w = _working_plant(parts, scale).work
    s12 = np.linalg.svd(w.D12, compute_uv=False)
    s21 = np.linalg.svd(w.D21, compute_uv=False)
    return bool(s12.size and s21.size and s12[-1] > tol and s21[-1] > tol)


def _level_riccati(parts: PlantParts, scale: bool) -> _Level | None:
    """The optimal level by the Riccati gamma iteration (:func:`_riccati_level`)
    on the scaled plant, or None if it finds no feasible level."""
    lev = _working_plant(parts, scale)
    try:
        r = _riccati_level(lev.work)
    except (IllPosedError, np.linalg.LinAlgError, ValueError):
        return None
    if r is None:
        return None
    g, steps = r
    return replace(lev, gamma=g * lev.gscale, status="riccati", levels=[g * lev.gscale],
                   method=f"Riccati gamma iteration ({steps} steps of bisection on ZDG Thm 17.1)")


_EPS_REGULARISE = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)


def _regularised_search(P, nmeas, ncon, parts: PlantParts, scale: bool, tries: list,
                        eps_list=_EPS_REGULARISE):
    """Singular problems: central controllers of regularised plants (:func:`_regularised`).

    For each ``eps`` the level of the regularised plant is found by the Riccati
    gamma iteration and its central controller built 1e-4 above it; each one is
    verified on the closed loop with the original ``P``.  The regularised level
    is an upper bound of the singular one that falls towards it as ``eps``
    decreases, until the Riccati solutions lose accuracy; the verified
    controller with the lowest closed-loop norm is returned (a candidate dict
    of :func:`_search`, or None).  On the two-mass plant with ``D21 = 0`` this
    gives 0.8070 where the LMI level reads 0.8187 and its controller achieves 0.8175;
    on the model-based identification plants of the cracked rotor it is the only
    construction that reaches 1e-4 of the level on all of them."""
    base = _working_plant(parts, scale)
    best = None
    for eps in eps_list:
        pe = _regularised(base.work, float(eps))
        try:
            r = _riccati_level(pe)
        except (IllPosedError, np.linalg.LinAlgError, ValueError):
            r = None
        if r is None:
            tries.append({"construction": CENTRAL_REGULARISED, "eps": float(eps), "backoff": 1e-4,
                          "gamma_target": float("nan"), "error": "no level found by the Riccati gamma iteration"})
            continue
        lev = replace(base, work=pe, gamma=r[0] * base.gscale)
        n0 = len(tries)
        cand, _ = _search(P, nmeas, ncon, lev, [1e-4], tries, "", "coupling", 1.0, central=True, lmi=False)
        for t in tries[n0:]:
            t.update(construction=CENTRAL_REGULARISED, eps=float(eps))
        if cand is not None and cand["stable"]:
            cand["construction"] = f"{CENTRAL_REGULARISED} (eps = {eps:.0e})"
            if best is None or cand["value"] < best["value"]:
                best = cand
    return best


def _passes(c, level: float | None = None) -> bool:
    """A stable loop within its target; with ``level`` (a Riccati level) also not more
    than 0.1 % below it: a controller doing much better than the level proves that the
    gamma iteration went wrong (feasibility that is not monotone in gamma numerically,
    seen on plants with D21 ~ 1e-10), and the LMIs must take over."""
    ok = c is not None and c["stable"] and c["value"] <= c["gamma_target"] * (1 + 1e-6)
    if ok and level is not None:
        ok = c["value"] >= level * (1 - 1e-3)
    return ok


def _search(P, nmeas, ncon, lev: _Level, schedule, tries: list, solver, controller_objective, bound_factor,
            central: bool, lmi: bool, first=None):
    """Controllers at the back-off levels of ``schedule`` above ``lev.gamma``, each
    verified on the closed loop rebuilt from ``P`` (:func:`_verify`); stops at the
    first one that achieves its target and returns ``(candidate, passed)``: the
    stable candidate with the lowest closed-loop norm so far (a dict), and
    whether any candidate achieved its target.

    At each level the central controller comes first (where the Riccati
    solutions exist there), then the LMI reconstruction: the preferred objective,
    the other one, and ``X, Y`` bounded more tightly (solvers sometimes fail on
    one formulation and solve another cleanly)."""
    work0, gscale = lev.work, lev.gscale
    variants = []
    if lmi and lev.R is not None:
        bound = bound_factor * max(np.linalg.eigvalsh(_sym(lev.R)).max(), np.linalg.eigvalsh(_sym(lev.S)).max(),
                                   1.0)
        objectives = [controller_objective] + [o for o in ("coupling", "margin") if o != controller_objective]
        variants = [(o, bound) for o in objectives] + [("margin", bound * 1e-2)]
    best = first
    if first is not None and first["stable"] and first["value"] <= lev.gamma * (1 + schedule[0]) * (1 + 1e-6) \
            and lev.status != "riccati":
        return first, True     # a controller found before (regularised plant) already achieves the level
    for b in schedule:
        gK = lev.gamma * (1.0 + b)
        builders = []
        if central:
            builders.append((CENTRAL, None, None))
        builders += [(LMI_CONTROLLER, o, bnd) for o, bnd in variants]
        for construction, objective, bnd in builders:
            rec = {"construction": construction, "backoff": b, "gamma_target": gK}
            if objective is not None:
                rec.update(objective=objective, bound=bnd)
            try:
                if objective is None:
                    Ak, Bk, Ck, Dk, info = central_controller(work0, gK / gscale)
                else:
                    Ak, Bk, Ck, Dk, info = _controller_at(work0, gK / gscale, solver, bnd, objective=objective,
                                                         gscale=gscale)
                Ak, Bk, Ck, Dk = _add_d22(Ak, Bk, Ck, Dk, lev.D22)
            except (InfeasibleError, SolverError, IllPosedError, np.linalg.LinAlgError) as exc:
                tries.append({**rec, "error": str(exc)})
                continue
            if not all(np.all(np.isfinite(X)) for X in (Ak, Bk, Ck, Dk)):
                tries.append({**rec, "error": "controller construction gave non-finite matrices"})
                continue
            # undo the time scaling K(s) = K_w(s / alpha), then u = su * K_s(sy * y)
            ra = np.sqrt(lev.alpha)
            Ak, Bk, Ck = lev.alpha * Ak, ra * Bk, ra * Ck
            K = ss(Ak, Bk * lev.sy[None, :], lev.su[:, None] * Ck, lev.su[:, None] * Dk * lev.sy[None, :],
                   inputs=P.output_labels[-nmeas:], outputs=P.input_labels[-ncon:], name="K")
            CL, stable, maxre, value, wpk, sly, gpk, stab = _verify(P, K, nmeas, ncon)
            tries.append({**rec, "stable": stable, "closed_loop_norm": value, "stability": stab.message, **info})
            cand = {"K": K, "CL": CL, "stable": stable, "maxre": maxre, "value": value, "wpk": wpk, "sly": sly,
                    "gpk": gpk, "gamma_target": gK, "backoff": b, "construction": construction,
                    "stability": stab.message}
            if best is None or (stable and (not best["stable"] or value < best["value"])):
                best = cand
            if lev.status == "riccati" and stable and value < lev.gamma * (1 - 1e-3):
                return best, False    # the Riccati level is wrong (see _passes): no use going on
            if _passes(cand, lev.gamma if lev.status == "riccati" else None):
                # the lowest achieved norm so far: a near miss at a smaller back-off
                # (1e-5 above its target) beats a pass at the next one
                return best, True
    return best, False


#: a Riccati level this far below the plant's w -> z scale is 0 to double precision
_ZERO_LEVEL = 1e-12


def _zero_infimum(P, nmeas, ncon, lev: _Level, tries, solver, controller_objective, bound_factor, notes, best):
    r"""The Riccati conditions hold at every level (e.g. square ``D12``, ``D21`` with
    :math:`A - B_2 D_{12}^{-1} C_1` and :math:`A - B_1 D_{21}^{-1} C_2` stable:
    :math:`X_\infty = Y_\infty = 0`): the infimum is 0 and is not attained, the
    central controllers grow without bound as the level goes to 0.  Controllers are
    built at levels 1e-1, 1e-2, ... of the plant's w -> z scale until one fails its
    check; the lowest verified one is returned with its level."""
    found = None
    for k in range(1, 13):
        trial = replace(lev, gamma=lev.gscale * 10.0 ** -k, status="zero infimum")
        cand, ok = _search(P, nmeas, ncon, trial, [1e-4], tries, solver, controller_objective, bound_factor,
                           central=True, lmi=False)
        if not ok:
            break
        found = (cand, trial)
    if found is None:
        return best, False, lev
    notes.append(f"the Riccati conditions hold at every level: the optimal level is 0 and is not attained "
                 f"(controllers grow without bound as the level goes to 0); the controller returned is the "
                 f"lowest of the levels 1e-1, 1e-2, ... times {lev.gscale:.3g} that passed its check")
    return found[0], True, replace(found[1], method=lev.method + "; infimum 0, not attained")


# ----------------------------------------------------------------------------
# main entry point
# ----------------------------------------------------------------------------

_BACKOFFS = (1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3)


def _check_options(solver, backoff, max_backoff, controller_objective, bound_factor, method="auto"):
    """Named errors for bad keyword arguments of :func:`hinfsyn` (before any solver runs)."""
    if not isinstance(solver, str) or not solver:
        raise ModelError(f"solver must be a cvxpy solver name (a string), got {solver!r}")
    if solver.upper() not in cp.installed_solvers():
        raise ModelError(f"solver {solver!r} is not installed; installed: {', '.join(cp.installed_solvers())}")
    for name, v in (("backoff", backoff), ("max_backoff", max_backoff), ("bound_factor", bound_factor)):
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, float, np.integer, np.floating)) \
                or not np.isfinite(v) or v <= 0:
            raise ModelError(f"{name} must be a positive finite number, got {v!r}")
    if backoff > 1.0 or max_backoff > 1.0:
        raise ModelError(f"backoff and max_backoff are relative distances above the optimal level and must "
                         f"be at most 1 (100 %), got backoff={backoff!r}, max_backoff={max_backoff!r}")
    if controller_objective not in ("coupling", "margin"):
        raise ModelError(f"controller_objective must be 'coupling' or 'margin', got {controller_objective!r}")
    if method not in ("auto", "riccati", "lmi"):
        raise ModelError(f"method must be 'auto', 'riccati' or 'lmi', got {method!r}")


def _zero_level(P, parts, nmeas, ncon, notes, solver, scale, t0):
    """The exogenous input w reaches no state and no z (B1 = 0, D11 = 0), or z
    sees no state (C1 = 0, D11 = 0): every stabilizing controller gives the
    closed-loop norm 0, the optimal level.  The LMIs degenerate at level 0, so
    an observer-based stabilizing controller (two Riccati equations) is built
    instead and checked like the LMI controllers."""
    if scale:
        work, su, sy, _, alpha, _ = _scale(parts)
    else:
        work, su, sy, alpha = parts, np.ones(ncon), np.ones(nmeas), 1.0
    A, B2, C2 = work.A, work.B2, work.C2
    n = A.shape[0]
    try:
        X = sla.solve_continuous_are(A, B2, np.eye(n), np.eye(ncon))
        Y = sla.solve_continuous_are(A.T, C2.T, np.eye(n), np.eye(nmeas))
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise SolverError(f"H-infinity synthesis at the optimal level 0 (w reaches no z): the Riccati "
                          f"equations of the stabilizing observer-based controller failed ({exc})") from None
    F = B2.T @ X
    L = Y @ C2.T
    Ak, Bk, Ck, Dk = A - B2 @ F - L @ C2, L, -F, np.zeros((ncon, nmeas))
    Ak, Bk, Ck, Dk = _add_d22(Ak, Bk, Ck, Dk, work.D22)
    ra = np.sqrt(alpha)
    Ak, Bk, Ck = alpha * Ak, ra * Bk, ra * Ck
    K = ss(Ak, Bk * sy[None, :], su[:, None] * Ck, su[:, None] * Dk * sy[None, :],
           inputs=P.output_labels[-nmeas:], outputs=P.input_labels[-ncon:], name="K")
    CL, stable, maxre, value, wpk, sly, gpk, stab = _verify(P, K, nmeas, ncon)
    if not stable:
        raise SolverError("H-infinity synthesis at the optimal level 0 (w reaches no z): the observer-based "
                          f"controller does not stabilize the closed loop ({stab.message})")
    notes = list(notes) + ["the exogenous input w reaches no performance output z for any controller "
                           "(B1 = 0 and D21 = 0, or C1 = 0 and D12 = 0; D11 = 0): the optimal level is 0 and any stabilizing "
                           "controller attains it; an observer-based (LQG-type) controller is returned"]
    poles = np.linalg.eigvals(np.asarray(K.A, float)) if K.nstates else np.zeros(0)
    return HinfResult(K=K, CL=CL, gamma=0.0, gamma_target=0.0, closed_loop_norm=value,
                      closed_loop_norm_slycot=sly, closed_loop_norm_grid=gpk, peak_frequency=wpk,
                      stable=stable, max_closed_loop_real_part=maxre, controller_poles=poles,
                      backoff=0.0, notes=notes, solver=solver, seconds=time.perf_counter() - t0,
                      info={"tries": [], "level_method": "exact (w does not reach z)", "u_scaling": su,
                            "y_scaling": sy})


def hinfsyn(P, nmeas: int, ncon: int, *, solver: str = "CLARABEL", backoff: float = 1e-4,
            scale: bool = True, max_backoff: float = 0.3, refine: bool = True,
            controller_objective: str = "coupling", bound_factor: float = 1e3,
            method: str = "auto") -> HinfResult:
    r"""H-infinity synthesis (same argument order as :func:`control.hinfsyn`).

    The optimal level comes from the Riccati gamma iteration where the problem
    is regular and the iteration succeeds, from the LMIs otherwise; the
    controller is the central one (:func:`central_controller`) where the
    Riccati solutions exist at the target level, the LMI reconstruction
    otherwise.  Every controller is checked on the closed loop rebuilt from
    ``P`` (stability by the scale-aware rule of :func:`mutext.lti.stability`,
    norm recomputed); the first that achieves its target level is returned.
    ``info["level_method"]`` and ``construction`` say which routes were used.

    Parameters
    ----------
    P : control.StateSpace
        Generalized plant with inputs ``[w; u]`` and outputs ``[z; y]``
        (continuous time).
    nmeas : int
        Number of measurements ``y`` (the last outputs of ``P``).
    ncon : int
        Number of control inputs ``u`` (the last inputs of ``P``).
    solver : str
        cvxpy solver name (default Clarabel).
    backoff : float
        The controller is built at level ``gamma * (1 + backoff)``; a strictly
        suboptimal level keeps it well conditioned.  If the closed loop fails
        the check (unstable, or norm above the target level), the backoff is
        raised step by step (1e-4, 3e-4, 1e-3, ...) up to ``max_backoff``.
        Central controllers achieve their target to about 1e-8 relative on
        badly scaled random plants, so the first step normally suffices.
    scale : bool
        Balance the plant's states, rescale time and normalise ``u``, ``y``
        first (recommended).
    refine : bool
        On the LMI route, for regular problems, refine the LMI level by
        bisection on the exact Riccati existence conditions
        (:func:`riccati_feasible`).
    controller_objective : {"coupling", "margin"}
        How a point inside the controller LMI is chosen: "coupling" keeps
        ``I - XY`` far from singular (fewer needlessly fast controller poles);
        "margin" maximises a uniform margin of both LMIs.  The other one is
        tried if the first yields no stabilizing controller.
    bound_factor : float
        ``X`` and ``Y`` of the controller LMI are bounded by this factor times
        the largest eigenvalue of the level LMI solution.
    method : {"auto", "riccati", "lmi"}
        "auto": for regular problems (``D12`` full column rank, ``D21`` full
        row rank) the level by bisection on the Riccati conditions
        (:func:`riccati_feasible`) and the central controller; the LMIs
        (level and controller) where that fails or the problem is singular.
        "riccati": that route only (an error where it fails).  "lmi": the
        textbook LMI route only (level and controller from LMIs).

    Returns
    -------
    HinfResult
        Controller ``K``, closed loop ``CL``, optimal level ``gamma``, the
        independently recomputed closed-loop norm and the construction used.

    Raises
    ------
    ModelError
        Wrong port counts, non-finite entries, discrete-time plant.
    IllPosedError
        ``(A, B2)`` not stabilizable or ``(C2, A)`` not detectable.
    InfeasibleError, SolverError
        The LMIs could not be solved, or no controller passing the check was
        found (the message names the deciding closed-loop pole).

    Examples
    --------
    >>> from mutext.examples import two_mass
    >>> res = hinfsyn(two_mass.plant(), 1, 1)
    >>> round(res.gamma, 4)
    1.0069
    """
    t0 = time.perf_counter()
    _check_options(solver, backoff, max_backoff, controller_objective, bound_factor, method)
    P, parts, notes = check_plant(P, nmeas, ncon)
    if parts.n == 0:
        raise ModelError("P has no states: static H-infinity synthesis is not supported")
    # w reaches no z for any controller only when it enters nothing (B1 = 0, D21 = 0) or z reads
    # nothing (C1 = 0, D12 = 0); with B1 = 0 alone w still enters through the measurement (D21)
    if not np.any(parts.D11) and ((not np.any(parts.B1) and not np.any(parts.D21))
                                  or (not np.any(parts.C1) and not np.any(parts.D12))):
        return _zero_level(P, parts, nmeas, ncon, notes, solver, scale, t0)
    regular = not any(n.startswith(("D12 does not", "D21 does not", "[A - jwI")) for n in notes)
    if method == "riccati" and not regular:
        raise IllPosedError("method='riccati' needs D12 of full column rank, D21 of full row rank and no "
                            "rank loss of the plant's pencils on the imaginary axis; "
                            + "; ".join(n.split(":")[0] for n in notes if n.startswith(("D12", "D21", "[A - jwI")))
                            + " (use method='auto' or 'lmi')")
    if np.any(parts.D22):
        notes.append("D22 is nonzero: controller designed for D22 = 0 and corrected by K = K0 (I + D22 K0)^-1")
    # nearly singular D12 / D21 (smallest singular value below 1e-8 of the channel's gain in the
    # working coordinates) make the normalisation of the Riccati route meaningless: treated like
    # singular ones.  Milder cases are caught by the checks of the central controllers: the
    # model-based identification plants (D21 ~ 1e-10, about 1e-6 in working coordinates) gave
    # Riccati levels 80 times too high, which their own controllers expose (see _passes)
    well_posed = regular and _well_conditioned_d(parts, scale)
    if method == "riccati" and regular and not well_posed:
        notes.append("D12 or D21 is nearly singular (below 1e-8 of its channel): the Riccati route may be inaccurate")
    lev = _level_riccati(parts, scale) if ((well_posed and method == "auto") or method == "riccati") else None
    if lev is None:
        if method == "riccati":
            raise SolverError("H-infinity synthesis (method='riccati'): the gamma iteration found no level at "
                              f"which the Riccati conditions hold{_near_axis_hint(P)}")
        lev = _level(parts, notes, solver, scale, refine)
    schedule = [x for x in _BACKOFFS if backoff <= x <= max_backoff] or [backoff]
    tries = []
    best = None
    if not well_posed and method == "auto":
        best = _regularised_search(P, nmeas, ncon, parts, scale, tries)
    best, passed = _search(P, nmeas, ncon, lev, schedule, tries, solver, controller_objective, bound_factor,
                           central=regular and method != "lmi", lmi=method != "riccati", first=best)
    if not passed and lev.status == "riccati" and lev.gamma <= _ZERO_LEVEL * lev.gscale:
        best, passed, lev = _zero_infimum(P, nmeas, ncon, lev, tries, solver, controller_objective,
                                          bound_factor, notes, best)
    if not passed and method == "auto" and lev.R is None:
        # the Riccati route gave a level but no central controller passed the check:
        # the LMIs take over (level and controller), central controllers at the
        # LMI's level are tried once more
        notes.append(f"no central controller passed the check at the Riccati level {lev.gamma:.6g} (or one "
                     "did far better than it, so the gamma iteration was wrong); the LMI route and "
                     "regularised central controllers were used")
        lev = _level(parts, notes, solver, scale, refine)
        reg = _regularised_search(P, nmeas, ncon, parts, scale, tries)
        if reg is not None and (best is None or not best["stable"] or reg["value"] < best["value"]):
            best = reg
        best, passed = _search(P, nmeas, ncon, lev, schedule, tries, solver, controller_objective,
                               bound_factor, central=regular, lmi=True, first=best)
    gamma = lev.gamma
    if best is None or not best["stable"]:
        last = {}
        for t in tries:
            last[t["construction"] + (f" ({t['objective']})" if "objective" in t else "")] = \
                t.get("error") or f"closed loop at backoff {t['backoff']:g}: {t['stability']}"
        raise SolverError("H-infinity synthesis: no stabilizing controller passed the check "
                          f"(optimal level gamma={gamma:.6g}; {len(tries)} attempts at backoffs "
                          f"{schedule[0]:g}..{schedule[-1]:g}){_near_axis_hint(P)}; last outcome per construction: "
                          + "; ".join(f"{k}: {v}" for k, v in last.items()))
    K, CL, stable, maxre, value, wpk, sly, gpk, gK, b = (best[k] for k in (
        "K", "CL", "stable", "maxre", "value", "wpk", "sly", "gpk", "gamma_target", "backoff"))
    if gamma < lev.gamma_lmi * (1 - 1e-6) and value > lev.gamma_lmi * (1 + 1e-3):
        # check of the reported level against the achieved one: the Riccati
        # refinement lowered the level, but no controller comes near even the LMI's
        notes.append(f"the reported level {gamma:.6g} (Riccati refinement of the LMI level "
                     f"{lev.gamma_lmi:.6g}) is not confirmed by a controller: the best one achieves "
                     f"{value:.6g}; treat the level as uncertain between the two")
    if value > gK * (1 + 1e-6):
        notes.append(f"the best controller found achieves {value:.6g}, above the target level {gK:.6g}")
    elif b > 1e-3:
        notes.append(f"no controller passed the check closer to the optimum: the controller "
                     f"achieves {value:.6g}, {100 * (value / gamma - 1):.2g} % above the optimal level")
    if value < gamma * (1 - 1e-6) and lev.status == "zero infimum":
        gamma = value       # the level is 0; report what the returned controller proves
    elif value < gamma * (1 - 1e-6):
        # a verified controller proves a lower level than the level computation returned
        notes.append(f"the controller achieves {value:.6g}, below the computed level {gamma:.6g}: the level "
                     "was computed inaccurately (on singular problems the infimum is approached only "
                     "by high-gain controllers); gamma is set to the level this controller proves")
        gamma = value
    poles = np.linalg.eigvals(np.asarray(K.A, float)) if K.nstates else np.zeros(0)
    return HinfResult(K=K, CL=CL, gamma=gamma, gamma_target=gK, closed_loop_norm=value,
                      closed_loop_norm_slycot=sly, closed_loop_norm_grid=gpk, peak_frequency=wpk,
                      stable=stable, max_closed_loop_real_part=maxre, controller_poles=poles,
                      backoff=b, notes=notes, solver=solver, seconds=time.perf_counter() - t0,
                      info={"tries": tries, "level_status": lev.status, "levels": lev.levels,
                            "gamma_lmi": lev.gamma_lmi, "level_method": lev.method,
                            "state_scaling": lev.tstate, "u_scaling": lev.su, "y_scaling": lev.sy,
                            "stability": best["stability"]},
                      construction=best["construction"])
