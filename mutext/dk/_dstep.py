r"""The D step: the pointwise optimal scalings of a closed loop on a grid (all frequencies at once),
the admissible band of each block's scaling, and the rational fits for the next K step.
"""
from __future__ import annotations

import numpy as np

from ..errors import ModelError, SolverError
from ..mu import BlockStructure
from ._dscale import fit_dscale


def _scaled_norms(H, S: BlockStructure, X) -> np.ndarray:
    """sigma_max(D M D^-1) at each frequency; ``H`` is (nw, ncols, nrows), ``X`` the log
    scalings (nw, nblocks)."""
    A = np.exp(X[:, S.col_block])[:, :, None] * H * np.exp(-X[:, S.row_block])[:, None, :]
    return np.linalg.norm(A, 2, axis=(1, 2))


def _norms_and_grads(H, S: BlockStructure, X):
    """sigma_max(D M D^-1) and its log-derivatives in log d (one column per block)."""
    A = np.exp(X[:, S.col_block])[:, :, None] * H * np.exp(-X[:, S.row_block])[:, None, :]
    U, s, Vh = np.linalg.svd(A)
    m = X.shape[1]
    El = np.eye(m)[S.col_block]            # (ncols, m): z entry -> block
    Er = np.eye(m)[S.row_block]            # (nrows, m): w entry -> block
    g = np.abs(U[:, :, 0]) ** 2 @ El - np.abs(Vh[:, 0, :]) ** 2 @ Er
    return s[:, 0], g


def _sweep_upper(H, S: BlockStructure, X0=None, tol: float = 1e-6, max_iter: int = 2000,
                 radius: float = 8.0, progress=None):
    r"""Diagonal-D upper bound of mu at every frequency at once.

    The same problem as ``mu_upper(method="osborne")`` (minimise the convex
    :math:`\log\bar\sigma(e^XMe^{-X})` over one log scaling per block, the last
    fixed to 0) by a central-cut ellipsoid method run on all frequencies in
    parallel (one batched SVD per step), started from ``X0`` (the previous
    iteration's scalings) or from Osborne balancing.  Each value is
    :math:`\bar\sigma(DMD^{-1})` for the returned :math:`D`, so a valid bound.

    ``progress(fraction)``, if given, is called every 50 steps with the
    fraction of frequencies converged.

    Returns
    -------
    upper : (nw,) ndarray
    X : (nw, nblocks) ndarray
        Log scalings, last column 0.
    """
    nw = H.shape[0]
    m = len(S)
    if X0 is None:
        # Osborne balancing of the block-norm matrices (off-diagonal blocks
        # only; the floor keeps blocks that are zero from driving d to 0 or inf)
        Bn = np.empty((nw, m, m))
        for i in range(m):
            for j in range(m):
                Bn[:, i, j] = np.linalg.norm(H[:, S.col_slices[i], S.row_slices[j]], axis=(1, 2))
        floor = 1e-100 + 1e-12 * Bn.max(axis=(1, 2), keepdims=True)
        Bn[:, np.arange(m), np.arange(m)] = 0.0
        Bn += floor
        X0 = np.zeros((nw, m))
        for _ in range(30 if m > 1 else 0):
            for i in range(m):
                e = np.exp(X0)
                r = np.sqrt(np.sum((Bn[:, i, :] / e) ** 2, axis=1))
                c = np.sqrt(np.sum((Bn[:, :, i] * e) ** 2, axis=1))
                X0[:, i] = 0.5 * (np.log(c) - np.log(r))
    X0 = np.asarray(X0, float) - np.asarray(X0, float)[:, -1:]
    s, _ = _norms_and_grads(H, S, X0)
    best_f = np.log(np.maximum(s, 1e-300))
    best_X = X0.copy()
    n = m - 1
    if n == 0:
        return s, best_X
    X = X0.copy()
    P = np.repeat((radius ** 2 * np.eye(n))[None], nw, axis=0)
    lower = np.full(nw, -np.inf)
    active = np.ones(nw, bool)
    for step in range(max_iter):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        if progress is not None and step % 50 == 0:
            progress(1.0 - idx.size / nw)
        s, g = _norms_and_grads(H[idx], S, X[idx])
        f = np.log(np.maximum(s, 1e-300))
        better = f < best_f[idx]
        best_f[idx[better]] = f[better]
        best_X[idx[better]] = X[idx[better]]
        g = g[:, :-1]
        Pi = P[idx]
        Pg = np.einsum("kij,kj->ki", Pi, g)
        gPg = np.einsum("ki,ki->k", g, Pg)
        lower[idx] = np.maximum(lower[idx], f - np.sqrt(np.maximum(gPg, 0.0)))
        done = (gPg <= 1e-300) | (best_f[idx] - lower[idx] < tol)
        active[idx[done]] = False
        go = ~done
        Pg_n = Pg[go] / np.sqrt(gPg[go])[:, None]
        k = idx[go]
        X[k, :-1] -= Pg_n / (n + 1)
        if n == 1:
            # one free variable: the central cut halves the interval (bisection)
            P[k] = Pi[go] / 4.0
        else:
            P[k] = (n * n / (n * n - 1.0)) * (Pi[go] - (2.0 / (n + 1)) * Pg_n[:, :, None] * Pg_n[:, None, :])
    return np.exp(best_f), best_X


def _intervals(H, S: BlockStructure, X, level: float, reach: float, steps: int = 24):
    """For each free block k and frequency, the interval of log d_k (others at ``X``)
    where sigma_max(D M D^-1) <= level, clipped to ``X +/- reach``.  sigma_max is
    log-convex in log d_k, so each end is found by bisection."""
    nw, m = X.shape
    lo = np.empty((nw, m - 1))
    hi = np.empty((nw, m - 1))
    for k in range(m - 1):
        for sign, out in ((1.0, hi), (-1.0, lo)):
            a = np.zeros(nw)                 # feasible offset
            b = np.full(nw, reach)           # offset to test
            Xt = X.copy()
            Xt[:, k] = X[:, k] + sign * b
            ok = _scaled_norms(H, S, Xt) <= level
            a[ok] = b[ok]
            todo = ~ok
            if np.any(todo):
                bb = b.copy()
                for _ in range(steps):
                    mid = 0.5 * (a + bb)
                    Xt[:, k] = X[:, k] + sign * mid
                    good = _scaled_norms(H, S, Xt) <= level
                    a = np.where(todo & good, mid, a)
                    bb = np.where(todo & ~good, mid, bb)
            out[:, k] = X[:, k] + sign * a
    return lo, hi


#: a fit is good enough when it stays inside half of its admissible band (weighted
#: error <= 0.5); 1.0 leaves no slack for several blocks deviating together
_GOOD = 0.5


class _BlockFits:
    """The fits of one round of :func:`_d_step`, by (block, order), each made once: block
    ``k``'s band centre ``center[:, k]`` fitted with weight ``1 / half[:, k]`` (None where
    the fit failed)."""

    def __init__(self, omega, center, half, m, progress):
        self.omega, self.center, self.half, self.m, self.progress = omega, center, half, m, progress
        self.cache = {}

    def __call__(self, k, n):
        cache = self.cache
        if (k, n) not in cache:
            if self.progress is not None:
                self.progress(f"block {k + 1}/{self.m - 1}, order {n}")
            try:
                cache[k, n] = fit_dscale(self.omega, np.exp(self.center[:, k]), n, weight=1.0 / self.half[:, k])
            except (SolverError, ModelError, np.linalg.LinAlgError):
                cache[k, n] = None
        return cache[k, n]


def _d_step(omega, H, S: BlockStructure, X, upper, max_order: int, fit_tol: float,
            budget: int, reach: float = np.log(100.0), rounds: int = 4, progress=None):
    """Rational scalings for the next K step (see the module docstring).

    ``budget`` bounds the states the scalings add to the plant (a block of
    size ``rows x cols`` with a fit of order ``n`` adds ``n (rows + cols)``).
    Returns the list of fits (``None`` for the last block) and the peak of
    sigma_max(D_fit M D_fit^-1) on the grid, the level the next K step starts from.
    ``progress(text)``, if given, is called before each fit.
    """
    level = float(np.max(upper)) * (1.0 + fit_tol)
    lo, hi = _intervals(H, S, X, level, reach)
    center = 0.5 * (lo + hi)
    half = np.maximum(0.5 * (hi - lo), 1e-4)
    m = len(S)
    cost = [b.rows + b.cols for b in S.blocks]
    requested = [0] * (m - 1)
    best = None
    for _ in range(rounds):
        fit = _BlockFits(omega, center, half, m, progress)
        cur = []
        for k in range(m - 1):
            f = fit(k, requested[k])
            while f is None and requested[k] > 0:     # a failed order: fall back
                requested[k] -= 1
                f = fit(k, requested[k])
            if f is None:
                raise SolverError(f"D step: no D-scale fit succeeded for block {k} "
                                  f"({S.blocks[k].name or S.blocks[k].kind})")
            cur.append(f)
        # raise the order of the worst-fitted block while the state budget allows;
        # a fit counts as good when it stays inside half of its admissible band
        while True:
            used = sum(f.order * cost[k] for k, f in enumerate(cur))
            cand = [k for k in range(m - 1) if cur[k].error > _GOOD and requested[k] < max_order
                    and used - cur[k].order * cost[k] + (requested[k] + 1) * cost[k] <= budget]
            if not cand:
                break
            k = max(cand, key=lambda k: cur[k].error)
            requested[k] += 1
            f = fit(k, requested[k])
            if f is not None and f.error < cur[k].error:
                cur[k] = f
        fits = cur + [None]
        Xf = np.zeros_like(X)
        for k in range(m - 1):
            Xf[:, k] = np.log(np.abs(fits[k](omega)))
        sig = _scaled_norms(H, S, Xf)
        fpeak = float(sig.max())
        if best is None or fpeak < best[1]:
            best = (fits, fpeak)
        bad = sig > level * (1.0 + 0.25 * fit_tol)
        if not np.any(bad):
            break
        # the fits together exceed the level where each alone stays inside its
        # band: narrow the bands there and fit again
        half[bad] *= 0.4
    return best
