"""Frequency responses: accuracy and time of ``mutext.lti.freqresp``.

Prints one table: system, method, the largest relative error (Frobenius norm of
G(jw) per frequency) against two independent references, the same against
python-control's ``frequency_response`` (slycot TB05AD when installed), and the
CPU time (``time.process_time``, best of 5, one BLAS thread, the methods taking
turns in one process) for the whole grid.  The references:

* ``mpmath``: ``C (jwI - A)^-1 B + D`` by an LU solve in 50-digit arithmetic in
  the system's own coordinates, on a subset of the grid (every k-th frequency:
  41 of a stiff loop's 401, 10 below 100 states, 2 at 100 states, where one
  frequency takes 16 CPU-s);
* ``direct``: a dense complex solve per frequency in double precision, in the
  system's own coordinates, on the whole grid (it agrees with mpmath to 1e-12
  or better on the random and scaled systems, not on the stiff loops).

Methods: ``mutext`` (balancing by powers of two, then from 16 states up the
modal route with its componentwise backward-error check, done in blocks of
frequencies as matrix products; a batched complex LU where that check fails and
below 16 states; where the output cancels, one step of refinement in extended
precision), ``hess+bal`` (an earlier ``freqresp``: balancing, Hessenberg
form once, then batched LU solves), ``hess-solve`` (balancing, Hessenberg form
once, then the O(n^2) Hessenberg elimination per frequency that TB05AD does,
vectorised over frequencies in numpy), ``python-control`` and ``direct``.

Systems: random stable ones of growing order (``ct.rss`` seeded, 2 inputs, 2
outputs, 1000 frequencies over 1e-3..1e3 rad/s); the same with states rescaled
by factors drawn in 1e-8..1e8; the near-axis distillation plant of the tests
closed by slycot's H-infinity controller (poles from -1e-6 to -5.9e6 rad/s,
matrix balancing spans 1e11; 400 frequencies over 1e-8..1e9 plus DC); the
distillation column closed by dkpy's D-K controller (``dkpy loop``, 28 states,
poles from -1e-6 to -6.9e6 rad/s, balancing spans 1e17; 400 frequencies over
1e-9..1e9 plus DC; left out without dkpy).

Measured (2-core machine shared with other work; CPU ms, best of 5):

===================  ===============  ==========  ==========  ==========  =========
system               method           err mpmath  err direct  err p-ctrl  time [ms]
===================  ===============  ==========  ==========  ==========  =========
random n=4           mutext              5.0e-16     7.5e-16     1.1e-15       1.15
random n=4           hess+bal            3.7e-16     1.3e-15     1.1e-15       1.12
random n=4           hess-solve          5.4e-16     1.1e-15     1.3e-15       0.80
random n=4           python-control      5.0e-16     1.1e-15     0.0e+00       7.76
random n=4           direct              5.0e-16     0.0e+00     1.1e-15      15.15
random n=10          mutext              5.3e-13     0.0e+00     3.9e-12       3.59
random n=10          hess+bal            2.3e-12     3.6e-12     4.2e-13       4.00
random n=10          hess-solve          2.3e-12     3.9e-12     6.4e-15       2.16
random n=10          python-control      2.3e-12     3.9e-12     0.0e+00       8.43
random n=10          direct              5.3e-13     0.0e+00     3.9e-12      17.79
random n=30          mutext              8.4e-14     2.0e-13     1.1e-13       4.53
random n=30          hess+bal            7.0e-14     2.1e-13     9.3e-14      22.02
random n=30          hess-solve          7.1e-14     2.1e-13     9.3e-14      11.65
random n=30          python-control      6.3e-14     1.7e-13     0.0e+00      10.57
random n=30          direct              7.6e-14     0.0e+00     1.7e-13      29.52
random n=100         mutext              9.1e-13     3.1e-12     2.4e-12      21.35
random n=100         hess+bal            8.5e-13     3.3e-12     2.2e-12     272.55
random n=100         hess-solve          8.2e-13     3.2e-12     2.2e-12     105.28
random n=100         python-control      1.4e-12     5.4e-12     0.0e+00      33.37
random n=100         direct              5.6e-13     0.0e+00     5.4e-12     203.61
scaled 1e+-8 n=10    mutext              4.7e-15     1.0e-14     1.9e-10       3.08
scaled 1e+-8 n=10    hess+bal            1.2e-14     1.7e-14     1.9e-10       3.33
scaled 1e+-8 n=10    hess-solve          1.2e-14     1.8e-14     1.9e-10       1.99
scaled 1e+-8 n=10    python-control      1.4e-10     1.9e-10     0.0e+00       8.17
scaled 1e+-8 n=10    direct              2.4e-15     0.0e+00     1.9e-10      17.13
scaled 1e+-8 n=30    mutext              2.5e-14     2.6e-13     8.0e+00       4.88
scaled 1e+-8 n=30    hess+bal            3.3e-14     3.0e-13     8.0e+00      23.31
scaled 1e+-8 n=30    hess-solve          3.0e-14     2.9e-13     8.0e+00      12.67
scaled 1e+-8 n=30    python-control      2.0e+00     3.4e+00     0.0e+00      10.54
scaled 1e+-8 n=30    direct              1.3e-13     0.0e+00     8.0e+00      29.35
stiff loop n=20      mutext              1.1e-10     5.6e-07     1.0e-04       9.34
stiff loop n=20      hess+bal            9.6e+05     9.6e+05     9.6e+05       4.62
stiff loop n=20      hess-solve          9.6e+05     9.6e+05     9.6e+05       3.19
stiff loop n=20      python-control      1.0e-04     1.0e-04     0.0e+00       4.39
stiff loop n=20      direct              2.3e-07     0.0e+00     1.0e-04      10.21
dkpy loop n=28       mutext              2.2e-09     8.9e-02     3.9e-01      16.83
dkpy loop n=28       hess+bal            6.3e+09     6.7e+09     7.5e+09       7.28
dkpy loop n=28       hess-solve          6.3e+09     6.7e+09     7.5e+09       5.31
dkpy loop n=28       python-control      3.3e-01     3.4e-01     0.0e+00       4.64
dkpy loop n=28       direct              6.5e-02     0.0e+00     3.9e-01      11.41
===================  ===============  ==========  ==========  ==========  =========

At 100 states ``mutext`` takes 0.64x python-control's time (21.4 against 33.4
ms; 44 ms before its modal route's products and backward-error check were done
in blocks of frequencies as matrix products); below 16 states it solves by LU
and stays 2-7x ahead.  The two stiff loops are where the others fail: their
output ``C X + D`` cancels by up to 1e8 (slycot's controller) and 4e10 (dkpy's)
against ``|C||X|``, so that rounding X to double precision alone costs that
many digits.  ``mutext`` refines X there with a residual in extended precision
and sums the output in extended precision: 1.1e-10 and 2.2e-9 against mpmath
(1.5e-7 and 4.7e-6 without; the goal was 1e-6), at 2-3x the time of the
unrefined evaluation (9.3 and 16.8 ms; python-control takes 4.4 and 4.6 ms
and is off by 1e-4 and 0.33).  The double-precision direct solve is off by
2.3e-7 and 6.5e-2 there, so only mpmath can judge these rows.  python-control's
error on the scaled n=30 system (2.0) comes with its Hessenberg evaluation;
balanced first, the Hessenberg routes (``hess+bal``, ``hess-solve``) are right
on the scaled systems but off by 1e6..1e10 on the stiff loops, where balancing
spreads the state scales over 1e11..1e17.  ``hess-solve`` in numpy (a Python
loop over the n elimination steps) is 5x slower than the modal route at 100
states.

Run: ``.venv/bin/python benchmarks/bench_freqresp.py``.
"""
from __future__ import annotations

import time
import warnings
from pathlib import Path

import control as ct
import numpy as np
import scipy.linalg as sla

from mutext.lti import blas_single_thread, freqresp, lft_lower, ss


def direct(sys, w):
    A, B, C, D = (np.asarray(X, float) for X in (sys.A, sys.B, sys.C, sys.D))
    n = A.shape[0]
    return np.stack([C @ np.linalg.solve(1j * x * np.eye(n) - A, B) + D for x in w], axis=-1)


def mp_response(sys, w, dps=50):
    """``C (jwI - A)^-1 B + D`` by an LU solve in ``dps``-digit arithmetic (mpmath), shape (p, m, len(w))."""
    import mpmath as mp
    A, B, C, D = (np.asarray(X, float) for X in (sys.A, sys.B, sys.C, sys.D))
    n = A.shape[0]
    out = np.empty((C.shape[0], B.shape[1], len(w)), complex)
    with mp.workdps(dps):
        Am, Bm, Cm = mp.matrix(A.tolist()), mp.matrix(B.tolist()), mp.matrix(C.tolist())
        for k, wk in enumerate(w):
            M = -Am
            for i in range(n):
                M[i, i] += mp.mpc(0, wk)
            for j in range(B.shape[1]):
                y = Cm * mp.lu_solve(M, Bm[:, j])
                out[:, j, k] = [complex(y[i]) for i in range(C.shape[0])]
    return out + D[:, :, None]


def _balanced_hessenberg(sys):
    A, B, C, D = (np.asarray(X, float) for X in (sys.A, sys.B, sys.C, sys.D))
    _, (sc, _) = sla.matrix_balance(A, permute=False, separate=True)
    A, B, C = A / sc[:, None] * sc[None, :], B / sc[:, None], C * sc[None, :]
    H, Q = sla.hessenberg(A, calc_q=True)
    return H, Q.T @ B, C @ Q, D


def hess_bal(sys, w):
    """An earlier freqresp of mutext: balancing, Hessenberg form once, then batched LU solves."""
    H, B, C, D = _balanced_hessenberg(sys)
    X = np.linalg.solve(1j * w[:, None, None] * np.eye(H.shape[0]) - H[None], B[None])
    return np.moveaxis(C[None] @ X, 0, -1) + D[:, :, None]


def hess_solve(sys, w, chunk=256):
    """Balancing, Hessenberg form once, then per frequency the O(n^2) elimination of TB05AD (partial
    pivoting between neighbouring rows) and back substitution, vectorised over frequencies."""
    H, B, C, D = _balanced_hessenberg(sys)
    n, m = B.shape
    out = np.empty((C.shape[0], m, w.size), complex)
    for s in range(0, w.size, chunk):
        ws = w[s:s + chunk]
        M = np.broadcast_to(-H[:, :, None], (n, n, ws.size)).astype(complex)     # (row, column, frequency)
        M[np.arange(n), np.arange(n)] += 1j * ws
        b = np.broadcast_to(B[:, :, None], (n, m, ws.size)).astype(complex)
        for i in range(n - 1):
            swap = np.abs(M[i + 1, i]) > np.abs(M[i, i])
            if swap.any():
                top, bot, bt, bb = M[i, i:].copy(), M[i + 1, i:].copy(), b[i].copy(), b[i + 1].copy()
                M[i, i:], M[i + 1, i:] = np.where(swap, bot, top), np.where(swap, top, bot)
                b[i], b[i + 1] = np.where(swap, bb, bt), np.where(swap, bt, bb)
            lik = M[i + 1, i] / M[i, i]
            M[i + 1, i + 1:] -= lik * M[i, i + 1:]
            b[i + 1] -= lik * b[i]
        x = np.empty_like(b)
        for i in range(n - 1, -1, -1):
            x[i] = (b[i] - np.einsum("jf,jmf->mf", M[i, i + 1:], x[i + 1:])) / M[i, i]
        out[:, :, s:s + ws.size] = np.einsum("pn,nmf->pmf", C, x)
    return out + D[:, :, None]


def pyctrl(sys, w):
    w = np.where(w == 0, 1e-300, w)  # python-control refuses w = 0 on some releases
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return ct.frequency_response(ct.ss(sys.A, sys.B, sys.C, sys.D), w).complex.reshape(
            sys.noutputs, sys.ninputs, -1)


def relerr(G, R):
    return float(np.max(np.linalg.norm(G - R, axis=(0, 1)) / np.linalg.norm(R, axis=(0, 1))))


def systems():
    """``(name, system, grid, every)``: the mpmath reference is taken on ``grid[::every]``."""
    rng = np.random.default_rng(20)
    np.random.seed(20)          # ct.rss draws from numpy's global generator
    w = np.logspace(-3, 3, 1000)
    for n in (4, 10, 30, 100):
        G = ct.rss(n, 2, 2)
        G = ss(G.A, G.B, G.C, rng.standard_normal((2, 2)))
        yield f"random n={n}", G, w, (111 if n < 100 else 999)
    for n in (10, 30):
        G = ct.rss(n, 2, 2)
        t = 10.0 ** rng.uniform(-8, 8, n)
        A, B, C = (np.asarray(X, float) for X in (G.A, G.B, G.C))
        yield (f"scaled 1e+-8 n={n}",
               ss(A / t[:, None] * t[None, :], B / t[:, None], C * t[None, :], rng.standard_normal((2, 2))), w, 111)
    data = np.load(Path(__file__).resolve().parent.parent / "tests" / "data" / "near_axis_plant.npz")
    P = ss(data["A"], data["B"], data["C"], data["D"])
    K = ct.hinfsyn(P, 2, 2)[0]
    yield "stiff loop n=20", lft_lower(P, K, 2, 2), np.concatenate([[0.0], np.logspace(-8, 9, 400)]), 10
    loop = dkpy_loop()
    if loop is not None:
        yield f"dkpy loop n={loop.nstates}", loop, np.concatenate([[0.0], np.logspace(-9, 9, 400)]), 10


def dkpy_loop():
    """The distillation column (``mutext.examples.distillation``, as ``dkpy.example_skogestad2006_p325``
    builds it) closed by dkpy's D-K controller (fixed order 4, 3 iterations, slycot's synthesis, 61
    frequencies over 1e-3..1e3 rad/s, as ``bench_dk.py`` runs it); None without dkpy."""
    try:
        import dkpy
    except ImportError:
        return None
    from threadpoolctl import threadpool_limits

    from mutext.examples import distillation
    P = distillation.plant()
    it = dkpy.DkIterFixedOrder(controller_synthesis=dkpy.HinfSynSlicot(),
                               structured_singular_value=dkpy.SsvLmiBisection(n_jobs=1),
                               d_scale_fit=dkpy.DScaleFitSlicot(), n_iterations=3, fit_order=4)
    blocks = [dkpy.ComplexFullBlock(1, 1), dkpy.ComplexFullBlock(1, 1), dkpy.ComplexFullBlock(2, 2)]
    with threadpool_limits(1), np.errstate(all="ignore"):
        K = it.synthesize(ct.ss(P.A, P.B, P.C, P.D), 2, 2, np.logspace(-3, 3, 61), blocks)[0]
    return lft_lower(P, K, 2, 2)


def main(reps: int = 5):
    methods = {"mutext": freqresp, "hess+bal": hess_bal, "hess-solve": hess_solve, "python-control": pyctrl,
               "direct": direct}
    print(f"{'system':20s} {'method':15s} {'err mpmath':>10s} {'err direct':>10s} {'err p-ctrl':>10s} "
          f"{'time [ms]':>10s}")
    with blas_single_thread():
        for name, sys, w, every in systems():
            Rm, R, Rc = mp_response(sys, w[::every]), direct(sys, w), pyctrl(sys, w)
            best = dict.fromkeys(methods, np.inf)
            for _ in range(reps):                          # the methods take turns: same load on each
                for m, f in methods.items():
                    t0 = time.process_time()
                    f(sys, w)
                    best[m] = min(best[m], time.process_time() - t0)
            for m, f in methods.items():
                G = f(sys, w)
                print(f"{name:20s} {m:15s} {relerr(G[:, :, ::every], Rm):10.1e} {relerr(G, R):10.1e} "
                      f"{relerr(G, Rc):10.1e} {1e3 * best[m]:10.2f}")
            print()


if __name__ == "__main__":
    main()
