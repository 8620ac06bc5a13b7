"""Benchmark: bounds on the structured singular value (mutext.mu) on seeded random problems.

For every case (a random block structure of 1-4 blocks, full / repeated complex
scalar / repeated real scalar, and a random complex matrix; case ``i`` uses the
seed ``seed + i``):

* ``lmi``: :func:`mutext.mu.mu_upper` with ``method="lmi"`` (D-G scalings when
  the structure has real blocks), and its method tag;
* ``osborne``: the independent diagonal-D bound (Osborne balancing + ellipsoid);
* ``fast``: :func:`mutext.mu.mu_upper` with ``method="fast"`` (the same D-G
  scalings as the LMI by a quasi-Newton descent, no SDP);
* ``lower``: the lower bound of :func:`mutext.mu.mu_bounds` and its method tag
  (:func:`mutext.mu.mu_lower`, restarted from the upper bound's scalings
  when the two do not meet);
* ``gap`` = (lmi - lower) / lmi, the relative width of the bracket on mu;
* ``cert``: relative difference between the returned bound and the bound
  recomputed from its scalings (:func:`mutext.mu.dg_bound`), for both upper bounds.

Summary lines: the largest LMI-Osborne difference where diagonal D is optimal
(full and 1x1 complex blocks: the two must agree), the gap (median and worst)
overall, on the cases where the upper bound is known to equal mu (complex
blocks with 2S + F <= 3) and on structures with real blocks, and seconds per
evaluation of each method, the largest ratio fast/LMI (``t_low``: :func:`mutext.mu.mu_lower` alone;
``t_bnd``: :func:`mutext.mu.mu_bounds`, lower and LMI upper together).

Usage::

    python benchmarks/bench_mu.py [--count 50] [--seed 0]
"""
from __future__ import annotations

import argparse
import time

import numpy as np


def random_case(seed: int):
    from mutext.mu import Block, BlockStructure
    rng = np.random.default_rng(seed)
    blocks = []
    for _ in range(int(rng.integers(1, 5))):
        kind = rng.choice(["full", "scalar", "real"], p=[0.4, 0.35, 0.25])
        if kind == "full":
            blocks.append(Block.full(int(rng.integers(1, 3)), int(rng.integers(1, 3))))
        else:
            blocks.append(Block(str(kind), *(2 * [int(rng.choice([1, 1, 2]))])))
    S = BlockStructure(blocks)
    M = rng.standard_normal((S.ncols, S.nrows)) + 1j * rng.standard_normal((S.ncols, S.nrows))
    return S, M


def exact_case(S) -> bool:
    """Complex structure with 2S + F <= 3 (S repeated scalars, F full or 1x1 blocks)."""
    if S.has_real:
        return False
    reps = sum(1 for b in S.blocks if b.kind == "scalar" and b.rows > 1)
    return 2 * reps + (len(S) - reps) <= 3


def timed(fn, *args, **kw):
    t0 = time.perf_counter()
    out = fn(*args, **kw)
    return out, time.perf_counter() - t0


def short(S) -> str:
    parts = []
    for b in S.blocks:
        parts.append(f"F{b.rows}x{b.cols}" if b.kind == "full" else f"{'C' if b.kind == 'scalar' else 'R'}{b.rows}")
    return " ".join(parts)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--count", type=int, default=50, help="number of random cases (default 50)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the first case (default 0)")
    args = ap.parse_args(argv)

    from mutext.errors import MutextError
    from mutext.mu import dg_bound, mu_bounds, mu_lower, mu_upper

    # build and compile the LMI once so that the first timing is not the compile time
    S0, M0 = random_case(args.seed)
    mu_upper(M0, S0)

    rows = []
    hdr = (f"{'case':>4} {'structure':<22} {'lmi':>9} {'tag':<7} {'osborne':>9} {'fast':>9} {'lower':>9} "
           f"{'tag':<11} {'gap':>8} {'cert':>8} {'t_lmi':>7} {'t_osb':>7} {'t_fast':>7} {'t_low':>7} "
           f"{'t_bnd':>7}")
    print(hdr)
    print("-" * len(hdr))
    for i in range(args.count):
        S, M = random_case(args.seed + i)
        try:
            _, t_low = timed(mu_lower, M, S)
            up, t_lmi = timed(mu_upper, M, S, method="lmi")
            osb, t_osb = timed(mu_upper, M, S, method="osborne")
            fst, t_fast = timed(mu_upper, M, S, method="fast")
            bnd, t_bnd = timed(mu_bounds, M, S)
            lo = bnd.lower
        except MutextError as exc:
            print(f"{i:>4} {short(S):<22} error: {type(exc).__name__}: {str(exc)[:60]}")
            continue
        cert = max(abs(dg_bound(M, S, r.Dl, r.Dr, r.G) - r.value) / max(r.value, 1e-300)
                   for r in (up, osb, fst))
        gap = (up.value - lo.value) / up.value if up.value > 0 else 0.0
        rows.append(dict(S=S, lmi=up.value, osb=osb.value, fast=fst.value, low=lo.value, gap=gap, cert=cert,
                         t_lmi=t_lmi, t_osb=t_osb, t_fast=t_fast, t_low=t_low, t_bnd=t_bnd))
        print(f"{i:>4} {short(S):<22} {up.value:9.5f} {up.method:<7} {osb.value:9.5f} {fst.value:9.5f} "
              f"{lo.value:9.5f} {lo.method:<11} {gap:8.2e} {cert:8.1e} {t_lmi:7.3f} {t_osb:7.3f} {t_fast:7.3f} "
              f"{t_low:7.3f} {t_bnd:7.3f}")
        if lo.value > up.value * (1 + 1e-8):
            print("      ** lower bound above upper bound **")

    if not rows:
        return 1
    print()
    diag = [r for r in rows if r["S"].diagonal_scalings and not r["S"].has_real]
    if diag:
        d = max(abs(r["lmi"] - r["osb"]) / r["lmi"] for r in diag if r["lmi"] > 0)
        print(f"LMI vs Osborne where diagonal D is optimal ({len(diag)} cases): "
              f"max relative difference {d:.2e}")
    print(f"LMI below Osborne in all cases: {all(r['lmi'] <= r['osb'] * (1 + 1e-6) for r in rows)}")
    print(f"fast / LMI: largest {max(r['fast'] / r['lmi'] for r in rows if r['lmi'] > 0):.8f}, "
          f"smallest {min(r['fast'] / r['lmi'] for r in rows if r['lmi'] > 0):.8f}")
    print(f"certificates: max relative difference of bound and recomputed bound "
          f"{max(r['cert'] for r in rows):.1e}")
    groups = [("all", rows), ("exact (2S+F<=3, complex)", [r for r in rows if exact_case(r["S"])]),
              ("complex, not exact", [r for r in rows if not r["S"].has_real and not exact_case(r["S"])]),
              ("with real blocks", [r for r in rows if r["S"].has_real])]
    print(f"{'gap (upper-lower)/upper':<34} {'cases':>5} {'median':>9} {'worst':>9}")
    for name, g in groups:
        if g:
            gaps = np.array([r["gap"] for r in g])
            print(f"  {name:<32} {len(g):>5} {np.median(gaps):9.2e} {gaps.max():9.2e}")
    print(f"{'seconds per evaluation':<34} {'mean':>9} {'median':>9} {'max':>9}")
    for key, name in (("t_lmi", "LMI upper (cvxpy/Clarabel)"), ("t_osb", "Osborne upper"),
                      ("t_fast", "fast D-G upper (BFGS)"),
                      ("t_low", "lower bound"), ("t_bnd", "mu_bounds (lower + LMI)")):
        t = np.array([r[key] for r in rows])
        print(f"  {name:<32} {t.mean():9.4f} {np.median(t):9.4f} {t.max():9.4f}")
    bad = sum(r["low"] > r["lmi"] * (1 + 1e-8) for r in rows)
    print(f"lower > upper: {bad} cases")
    return 0 if bad == 0 else 1


if __name__ == "__main__":
    raise SystemExit(main())
