r"""Upper bound by diagonal scalings: Osborne balancing, then the ellipsoid method ([SO]_).

The function :math:`x\mapsto\log\bar\sigma(e^XMe^{-X})` is convex; it is minimised
with its exact subgradient (``mu_upper(method="osborne")``, and the starting
scalings of the LMI and fast bounds).
"""
from __future__ import annotations

import math

import numpy as np

from ._structure import BlockStructure


def _osborne(M, S: BlockStructure, iterations: int = 30, tol: float = 0.0) -> np.ndarray:
    """Log-scalings (one per block) that balance the matrix of block norms (Osborne).

    Only a starting point for the ellipsoid method.  Zero block norms are
    replaced by 1e-14 of the largest one, so that a reducible pattern (a
    triangular M, whose infimum over D is not attained) still gives finite,
    strongly graded scalings; they are kept within exp(+-30).  With ``tol > 0`` the sweeps
    stop once no log-scaling moves by more than ``tol``.
    """
    m = len(S)
    if m == 1:
        return np.zeros(1)
    # squared Frobenius norms of the blocks M_ij (rows of block i's outputs, columns of block j's inputs)
    A2 = M.real ** 2 + M.imag ** 2 if np.iscomplexobj(M) else np.asarray(M, float) ** 2
    B2 = np.eye(m)[S.col_block].T @ A2 @ np.eye(m)[S.row_block]
    np.fill_diagonal(B2, 0.0)
    top = B2.max()
    if top == 0:
        return np.zeros(m)
    B2 = np.maximum(B2 / top, 1e-28)             # the block norms floored at 1e-14 of the largest
    np.fill_diagonal(B2, 0.0)
    # the sweeps on Python floats: m is small and the loop is sequential (Gauss-Seidel)
    b2 = B2.tolist()
    x = [0.0] * m
    e2 = [1.0] * m
    inv = [1.0] * m
    rng = range(m)
    for _ in range(iterations):
        moved = 0.0
        for i in rng:
            row = b2[i]
            r2 = sum(row[j] * inv[j] for j in rng)       # row i of D B D^-1, squared, without d_i
            c2 = sum(b2[j][i] * e2[j] for j in rng)      # column i, without 1/d_i
            xi = min(max(0.25 * (math.log(c2) - math.log(r2)), -30.0), 30.0)
            moved = max(moved, abs(xi - x[i]))
            x[i] = xi
            e2[i] = math.exp(2.0 * xi)
            inv[i] = 1.0 / e2[i]
        if moved <= tol:
            break
    return np.array(x) - x[-1]


def _sigma_and_grad(M, S, x):
    r""":math:`\bar\sigma(e^X M e^{-X})` and the gradient of its logarithm, :math:`|u_k|^2 - |v_k|^2`."""
    # in the log domain, scaled by the largest entry: exp(x) overflowing (and 0 * inf)
    # made the SVD fail for badly scaled M
    absM = np.abs(M)
    nz = absM > 0
    if not nz.any():
        m = len(x)
        return 0.0, np.zeros(m)
    with np.errstate(divide="ignore"):
        logA = np.where(nz, x[S.col_block][:, None] - x[S.row_block][None, :] + np.log(np.where(nz, absM, 1.0)),
                        -np.inf)
    L = float(logA.max())
    A = np.where(nz, np.exp(logA - L) * (M / np.where(nz, absM, 1.0)), 0.0)
    U, s, Vh = np.linalg.svd(A)
    with np.errstate(over="ignore", invalid="ignore"):
        s0 = 0.0 if s[0] == 0 else float(s[0] * np.exp(L))
    m = len(x)
    g = (np.bincount(S.col_block, np.abs(U[:, 0]) ** 2, minlength=m)
         - np.bincount(S.row_block, np.abs(Vh[0]) ** 2, minlength=m))
    return s0, g


def _ellipsoid(M, S: BlockStructure, x0, tol: float, max_iter: int, radius: float):
    """Minimise log sigma_max over the free log-scalings x (last block fixed to 0) in the
    ball of the given radius around x0.  Returns (best f, best x, iterations)."""
    n = len(S) - 1
    x = x0[:-1].copy()
    s0, _ = _sigma_and_grad(M, S, x0)
    if s0 == 0.0:
        return -np.inf, x, 0
    best_f, best_x = np.log(s0), x.copy()
    if n == 1:
        # one free variable: bisection on the sign of the subgradient
        lo, hi = x[0] - radius, x[0] + radius
        it = 0
        while hi - lo > tol and it < 200:
            it += 1
            mid = 0.5 * (lo + hi)
            s, g = _sigma_and_grad(M, S, np.array([mid, 0.0]))
            if s > 0 and np.log(s) < best_f:
                best_f, best_x = np.log(s), np.array([mid])
            if g[0] > 0:
                hi = mid
            elif g[0] < 0:
                lo = mid
            else:
                break
        return best_f, best_x, it
    # central-cut ellipsoid method; f - sqrt(g'Pg) is a lower bound on the minimum
    # over the current ellipsoid, which gives the stopping test
    P = radius ** 2 * np.eye(n)
    lower = -np.inf
    it = 0
    for it in range(1, max_iter + 1):
        s, g = _sigma_and_grad(M, S, np.append(x, 0.0))
        if s <= 0:
            return -np.inf, x, it
        f = np.log(s)
        if f < best_f:
            best_f, best_x = f, x.copy()
        g = g[:-1]
        gPg = float(g @ P @ g)
        if gPg <= 1e-300:
            break
        lower = max(lower, f - np.sqrt(gPg))
        if best_f - lower < tol:
            break
        gt = g / np.sqrt(gPg)
        Pg = P @ gt
        x = x - Pg / (n + 1)
        P = (n * n / (n * n - 1.0)) * (P - (2.0 / (n + 1)) * np.outer(Pg, Pg))
        P = 0.5 * (P + P.T)
    return best_f, best_x, it


def _upper_osborne(M, S: BlockStructure, tol: float = 1e-8, max_iter: int = 3000, radius: float = 12.0,
                   restarts: int = 4):
    """Minimise log sigma_max(D M D^-1) over one log-scaling per block (last fixed to 0).

    The ellipsoid method searches a ball around the Osborne scaling; when the
    best point lies near its edge (the infimum is approached as some d -> 0, as
    for a triangular M) the search is restarted around it.
    Returns (value, d, iterations); the caller recomputes the value from ``d``.
    """
    x0 = _osborne(M, S)
    if len(S) == 1:
        s0, _ = _sigma_and_grad(M, S, x0)
        return s0, np.exp(x0), 0
    total = 0
    for _ in range(restarts + 1):
        f, xb, it = _ellipsoid(M, S, x0, tol, max_iter, radius)
        total += it
        xb = np.append(xb, 0.0)
        if not np.isfinite(f):
            return 0.0, np.exp(xb), total
        moved = np.linalg.norm(xb - x0)
        x0 = xb
        if moved < 0.5 * radius:
            break
    return float(np.exp(f)), np.exp(x0), total
