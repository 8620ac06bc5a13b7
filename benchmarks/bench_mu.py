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
  recomputed from its scalings (:func:`mutext.mu.dg_bound`), for both upper bounds;
* ``auto``: the default :func:`mutext.mu.mu_upper` (``method="auto"``) and, where the
  structure is one SLICOT AB13MD takes (1 x 1 real, 1 x 1 complex, square full
  complex blocks) and slycot is installed, ``ab13md``: ``slycot.ab13md``'s bound, an
  independent reference (``-`` elsewhere).

Summary lines: the largest LMI-Osborne difference where diagonal D is optimal
(full and 1x1 complex blocks: the two must agree), the gap (median and worst)
overall, on the cases where the upper bound is known to equal mu (complex
blocks with 2S + F <= 3) and on structures with real blocks, and CPU seconds
(``time.process_time``) per evaluation of each method, the largest ratio fast/LMI
(``t_low``: :func:`mutext.mu.mu_lower` alone; ``t_bnd``: :func:`mutext.mu.mu_bounds`,
lower and LMI upper together); then the default bound against AB13MD: the ratio of
the values and the CPU milliseconds per matrix of each (best of ``--repeat`` runs).

Usage::

    python benchmarks/bench_mu.py [--count 50] [--seed 0] [--repeat 5]
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
    t0 = time.process_time()
    out = fn(*args, **kw)
    return out, time.process_time() - t0


def best_of(repeat: int, fn, *args, **kw):
    """(result, smallest CPU time of ``repeat`` calls): the machine's load only adds time."""
    out, best = timed(fn, *args, **kw)
    for _ in range(repeat - 1):
        best = min(best, timed(fn, *args, **kw)[1])
    return out, best


def ab13md_args(S):
    """``nblock``, ``itype`` of slycot.ab13md for the structure, None if AB13MD does not take it."""
    nb, it = [], []
    for b in S.blocks:
        if b.kind == "full" and b.rows == b.cols:
            nb.append(b.rows)
            it.append(2)
        elif b.rows == 1 and b.kind in ("scalar", "real"):
            nb.append(1)
            it.append(1 if b.kind == "real" else 2)
        else:
            return None
    return np.array(nb), np.array(it)


def short(S) -> str:
    parts = []
    for b in S.blocks:
        parts.append(f"F{b.rows}x{b.cols}" if b.kind == "full" else f"{'C' if b.kind == 'scalar' else 'R'}{b.rows}")
    return " ".join(parts)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--count", type=int, default=50, help="number of random cases (default 50)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the first case (default 0)")
    ap.add_argument("--repeat", type=int, default=5,
                    help="runs of the default bound and AB13MD per case, the fastest kept (default 5)")
    args = ap.parse_args(argv)
    try:
        from slycot import ab13md
    except ImportError:
        ab13md = None

    from mutext.errors import MutextError
    from mutext.mu import dg_bound, mu_bounds, mu_lower, mu_upper

    # build and compile the LMI once so that the first timing is not the compile time
    S0, M0 = random_case(args.seed)
    mu_upper(M0, S0)

    rows = []
    hdr = (f"{'case':>4} {'structure':<22} {'lmi':>9} {'tag':<7} {'osborne':>9} {'fast':>9} {'lower':>9} "
           f"{'tag':<11} {'gap':>8} {'cert':>8} {'t_lmi':>7} {'t_osb':>7} {'t_fast':>7} {'t_low':>7} "
           f"{'t_bnd':>7} {'auto':>9} {'ab13md':>9} {'t_auto':>7} {'t_ab13':>7}")
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
            auto, t_auto = best_of(args.repeat, mu_upper, M, S)
            ab_args = ab13md_args(S) if ab13md is not None else None
            ab, t_ab = (None, None) if ab_args is None else best_of(args.repeat, lambda: ab13md(M, *ab_args)[0])
        except MutextError as exc:
            print(f"{i:>4} {short(S):<22} error: {type(exc).__name__}: {str(exc)[:60]}")
            continue
        cert = max(abs(dg_bound(M, S, r.Dl, r.Dr, r.G) - r.value) / max(r.value, 1e-300)
                   for r in (up, osb, fst))
        gap = (up.value - lo.value) / up.value if up.value > 0 else 0.0
        rows.append(dict(S=S, lmi=up.value, osb=osb.value, fast=fst.value, low=lo.value, gap=gap, cert=cert,
                         t_lmi=t_lmi, t_osb=t_osb, t_fast=t_fast, t_low=t_low, t_bnd=t_bnd,
                         auto=auto.value, ab=ab, t_auto=t_auto, t_ab=t_ab))
        abcol = f"{'-':>9} {t_auto:7.4f} {'-':>7}" if ab is None else f"{ab:9.5f} {t_auto:7.4f} {t_ab:7.4f}"
        print(f"{i:>4} {short(S):<22} {up.value:9.5f} {up.method:<7} {osb.value:9.5f} {fst.value:9.5f} "
              f"{lo.value:9.5f} {lo.method:<11} {gap:8.2e} {cert:8.1e} {t_lmi:7.3f} {t_osb:7.3f} {t_fast:7.3f} "
              f"{t_low:7.3f} {t_bnd:7.3f} {auto.value:9.5f} {abcol}")
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
    ab_rows = [r for r in rows if r["ab"] is not None and len(r["S"]) > 1]
    if ab_rows:
        ratio = np.array([r["auto"] / r["ab"] for r in ab_rows if r["ab"] > 0])
        print(f"default (auto) vs AB13MD on {len(ab_rows)} AB13MD structures of more than one block: "
              f"value ratio {ratio.min():.9f} .. {ratio.max():.9f}")
        print(f"{'CPU ms per matrix':<34} {'mean':>9} {'median':>9} {'max':>9}")
        for key, name in (("t_auto", "default mu_upper"), ("t_ab", "slycot AB13MD")):
            t = 1e3 * np.array([r[key] for r in ab_rows])
            print(f"  {name:<32} {t.mean():9.3f} {np.median(t):9.3f} {t.max():9.3f}")
        print(f"  default slower than AB13MD on {sum(r['t_auto'] > r['t_ab'] for r in ab_rows)} of {len(ab_rows)}")
    bad = sum(r["low"] > r["lmi"] * (1 + 1e-8) for r in rows)
    print(f"lower > upper: {bad} cases")
    return 0 if bad == 0 else 1


if __name__ == "__main__":
    raise SystemExit(main())
