"""Frequency responses: accuracy and time of ``mutext.lti.freqresp``.

Prints one table: system, method, the largest relative error (Frobenius norm of
G(jw) per frequency) against a dense complex solve of ``C (jwI - A)^-1 B + D``
in the system's own coordinates (the reference; it agrees with 50-digit mpmath
to ~3e-7 on the stiff loop, to ~1e-14 on the others), the same against
python-control's ``frequency_response`` (slycot TB05AD when installed), and the
time (best of 3) for the whole grid.

Methods: ``mutext`` (balancing by powers of two, then from 16 states up the
modal route with its componentwise backward-error check, a batched complex LU
per frequency where that check fails and below 16 states), ``hess+bal`` (an earlier ``freqresp``:
balancing, Hessenberg form once, then solves; reproduced here for comparison),
``python-control`` and ``direct`` (the reference, a Python loop of dense solves).

Systems: random stable ones of growing order (``ct.rss``, 2 inputs, 2 outputs,
1000 frequencies over 1e-3..1e3 rad/s); the same with states rescaled by factors
drawn in 1e-8..1e8; the near-axis distillation plant of the tests closed by
slycot's H-infinity controller (poles from -1e-6 to -5.9e6 rad/s, matrix
balancing spans 1e11; 400 frequencies over 1e-8..1e9 plus DC).

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


def hess_bal(sys, w):
    """An earlier freqresp of mutext: balancing, Hessenberg form once, then solves."""
    A, B, C, D = (np.asarray(X, float) for X in (sys.A, sys.B, sys.C, sys.D))
    _, (sc, _) = sla.matrix_balance(A, permute=False, separate=True)
    A, B, C = A / sc[:, None] * sc[None, :], B / sc[:, None], C * sc[None, :]
    H, Q = sla.hessenberg(A, calc_q=True)
    X = np.linalg.solve(1j * w[:, None, None] * np.eye(A.shape[0]) - H[None], (Q.T @ B)[None])
    return np.moveaxis((C @ Q)[None] @ X, 0, -1) + D[:, :, None]


def pyctrl(sys, w):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return ct.frequency_response(ct.ss(sys.A, sys.B, sys.C, sys.D), w).complex.reshape(
            sys.noutputs, sys.ninputs, -1)


def relerr(G, R):
    return float(np.max(np.linalg.norm(G - R, axis=(0, 1)) / np.linalg.norm(R, axis=(0, 1))))


def best_time(f, reps=3):
    t = np.inf
    for _ in range(reps):
        t0 = time.perf_counter()
        f()
        t = min(t, time.perf_counter() - t0)
    return t


def systems():
    rng = np.random.default_rng(20)
    w = np.logspace(-3, 3, 1000)
    for n in (4, 10, 30, 100):
        G = ct.rss(n, 2, 2)
        G = ss(G.A, G.B, G.C, rng.standard_normal((2, 2)))
        yield f"random n={n}", G, w
    for n in (10, 30):
        G = ct.rss(n, 2, 2)
        t = 10.0 ** rng.uniform(-8, 8, n)
        A, B, C = (np.asarray(X, float) for X in (G.A, G.B, G.C))
        yield (f"scaled 1e+-8 n={n}",
               ss(A / t[:, None] * t[None, :], B / t[:, None], C * t[None, :], rng.standard_normal((2, 2))), w)
    data = np.load(Path(__file__).resolve().parent.parent / "tests" / "data" / "near_axis_plant.npz")
    P = ss(data["A"], data["B"], data["C"], data["D"])
    K = ct.hinfsyn(P, 2, 2)[0]
    yield "stiff loop n=20", lft_lower(P, K, 2, 2), np.concatenate([[0.0], np.logspace(-8, 9, 400)])


def main():
    methods = {"mutext": freqresp, "hess+bal": hess_bal, "python-control": pyctrl, "direct": direct}
    print(f"{'system':22s} {'method':15s} {'err vs direct':>14s} {'err vs p-ctrl':>14s} {'time [ms]':>10s}")
    with blas_single_thread():
        for name, sys, w in systems():
            R = direct(sys, w)
            wpc = np.where(w == 0, 1e-300, w)  # python-control refuses w = 0 on some releases
            Rc = pyctrl(sys, wpc)
            for m, f in methods.items():
                G = f(sys, wpc if m == "python-control" else w)
                t = best_time(lambda: f(sys, w if m != "python-control" else wpc))
                print(f"{name:22s} {m:15s} {relerr(G, R):14.2e} {relerr(G, Rc):14.2e} {1e3 * t:10.2f}")
            print()


if __name__ == "__main__":
    main()
