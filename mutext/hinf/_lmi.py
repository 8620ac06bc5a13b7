r"""The LMI route: the optimal level from the Gahinet-Apkarian LMIs and the controller
reconstructed from a point inside them (Scherer, Gahinet and Chilali).
"""
from __future__ import annotations

import cvxpy as cp
import numpy as np
import scipy.linalg as sla

from .._solver import solve
from ..errors import InfeasibleError, SolverError
from ._plant import _sym, PlantParts


def _solve(prob: cp.Problem, solver: str, what: str, gamma_hint=None, tight: bool = True):
    status = solve(prob, what, solver=solver, accuracy="tight" if tight else "loose")
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
