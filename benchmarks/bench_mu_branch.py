"""Benchmark: how far the D-G bounds sit above mixed mu, and what branch and bound closes, in one run.

Random complex matrices (seeded) with ``r`` real scalars and one full complex
block (``--structures``, e.g. ``2x1 3x1 3x2``: 3 real scalars and a 2x2 block).
For each matrix, on the same run:

* ``exact``: mixed mu by brute force over the real parameters
  (``_independent.mixed_mu_brute_force``: main loop theorem, a grid of the
  parameters with its four best points polished; independent of mutext);
* ``AB13MD``: SLICOT's mixed D-G upper bound;
* ``D-G``: :func:`mutext.mu.mu_upper` (``method="fast"``);
* ``branch``: :func:`mutext.mu.mu_upper_branch` (``rtol`` 1e-3);
* ``lower``: :func:`mutext.mu.mu_lower`.

Printed per structure: the median and largest excess over ``exact`` of each
upper bound, how many matrices have a D-G excess above 1 %, the median
seconds of each tool, and any matrix where a bound falls below ``exact`` by
more than 1e-6 (an invalid bound; none is expected).

Usage::

    python benchmarks/bench_mu_branch.py [--cases 20] [--structures 2x1 2x2 3x1 3x2] [--seed 0]
"""
from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

from _independent import mixed_mu_brute_force


def cases(nreal: int, ncomplex: int, count: int, seed: int):
    rng = np.random.default_rng(seed)
    n = nreal + ncomplex
    for _ in range(count):
        yield rng.standard_normal((n, n)) + 1j * rng.uniform(0, 1) * rng.standard_normal((n, n))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", type=int, default=20)
    ap.add_argument("--structures", nargs="+", default=["2x1", "2x2", "3x1", "3x2"])
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    # the brute force's line searches step through overflowing trial points on some matrices
    warnings.simplefilter("ignore", RuntimeWarning)

    from slycot import ab13md

    from mutext.mu import Block, BlockStructure, mu_lower, mu_upper, mu_upper_branch

    print(f"{'structure':>9} {'cases':>5} | {'excess over exact: median / max':^44} | "
          f"{'D-G >1%':>7} | {'median seconds':^38} | invalid")
    print(f"{'':>9} {'':>5} | {'AB13MD':>14} {'D-G':>14} {'branch':>14} | {'':>7} | "
          f"{'exact':>8} {'AB13MD':>8} {'D-G':>8} {'branch':>8} |")
    for spec in args.structures:
        nreal, ncomplex = (int(x) for x in spec.split("x"))
        S = BlockStructure([Block.real(1)] * nreal + [Block.full(ncomplex)])
        nb = np.array([1] * nreal + [ncomplex])
        it = np.array([1] * nreal + [2])
        rows, secs, invalid = [], [], 0
        for M in cases(nreal, ncomplex, args.cases, args.seed):
            t = [time.perf_counter()]
            exact = mixed_mu_brute_force(M, nreal, points=81 if nreal <= 2 else 21, polish=4)
            t.append(time.perf_counter())
            ref = ab13md(M, nb, it)[0]
            t.append(time.perf_counter())
            dg = mu_upper(M, S, method="fast").value
            t.append(time.perf_counter())
            br = mu_upper_branch(M, S).value
            t.append(time.perf_counter())
            low = mu_lower(M, S).value
            invalid += sum(v < exact * (1 - 1e-6) for v in (ref, dg, br)) + (low > exact * (1 + 1e-3))
            rows.append([ref / exact - 1, dg / exact - 1, br / exact - 1])
            secs.append(np.diff(t))
        r, s = np.array(rows), np.array(secs)

        def cell(x):
            return f"{np.median(x):6.2%}/{x.max():6.2%}"
        print(f"{spec:>9} {len(rows):>5} | {cell(r[:, 0]):>14} {cell(r[:, 1]):>14} {cell(r[:, 2]):>14} | "
              f"{int((r[:, 1] > 0.01).sum()):>7} | " + " ".join(f"{v:8.3f}" for v in np.median(s, axis=0))
              + f" | {invalid}")
    print("excess: (bound - exact) / exact, exact by brute force over the real parameters (a lower bound on mu "
          "that a fine grid makes tight; a negative excess of a few 1e-7 is the grid's)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
