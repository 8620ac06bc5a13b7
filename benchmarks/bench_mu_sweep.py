"""Benchmark: a mixed real/complex mu upper-bound sweep, mutext against SLICOT AB13MD, in one run.

The problem: a random stable 10-state system with 6 inputs and 6
outputs (seed 0), blocks ``r1 r1 C2x2 C1 C1`` (two real scalars, a full complex
2x2 block and two complex 1x1 blocks), ``--points`` log-spaced frequencies
from 1e-2 to 1e2 rad/s.  On the same frequencies:

* ``ab13md``: ``slycot.ab13md`` at each frequency (cold start: its warm start
  ``x`` argument made it hang on this problem);
* ``auto``: :func:`mutext.mu.mu_sweep` with its default ``method="auto"`` (the fast
  sweep below, every value checked against its scalings);
* ``fast``: :func:`mutext.mu.mu_sweep` with ``method="fast"`` (D-G scalings by
  warm-started BFGS, the values near the peak polished and the largest checked
  by the LMI), ``refine=False`` so that the frequencies are the same;
* ``osborne``: ``method="osborne"`` (diagonal D, real blocks as complex);
* ``lmi`` (``--lmi``, slow: about 0.2 s a frequency): ``method="lmi"``.

Printed: CPU seconds (``time.process_time``; run with one BLAS thread), peak, time and peak ratios against AB13MD, pointwise
ratios (median, max, number of frequencies more than 0.1 % above AB13MD) and whether the certificate at the peak
(:func:`mutext.mu.dg_bound` of the returned scalings) reproduces the peak, then a
summary table of the default sweep against AB13MD.

With ``--seeds N`` it prints instead one row for each of the problems of seeds 0 .. N-1 (the
default sweep and ``method="fast"`` against AB13MD: time ratio, largest pointwise ratio,
frequencies more than 0.1 % above AB13MD).

Usage::

    python benchmarks/bench_mu_sweep.py [--points 500] [--lmi] [--seed 0]
    python benchmarks/bench_mu_sweep.py --seeds 12 [--points 500]
"""
from __future__ import annotations

import argparse
import time

import numpy as np


def problem(seed: int):
    from mutext.lti import ss
    from mutext.mu import Block, BlockStructure
    rng = np.random.default_rng(seed)
    n = 10
    A = rng.standard_normal((n, n))
    A -= (np.linalg.eigvals(A).real.max() + 0.3) * np.eye(n)
    sys = ss(A, rng.standard_normal((n, 6)), rng.standard_normal((6, n)), rng.standard_normal((6, 6)))
    S = BlockStructure([Block.real(), Block.real(), Block.full(2), Block.full(1), Block.full(1)])
    return sys, S, np.array([1, 1, 2, 1, 1]), np.array([1, 1, 2, 2, 2])


def default_table(entries) -> str:
    """The summary table of the default sweep (``method="auto"``) against AB13MD: structure,
    size, frequencies, CPU seconds of both, their ratio, the peak ratio and whether the
    scalings returned at the peak reproduce it (:func:`mutext.mu.dg_bound`, 1e-9 relative)."""
    from mutext.lti import freqresp
    from mutext.mu import dg_bound
    hdr = (f"{'problem':<10} {'structure':<22} {'n':>3} {'freqs':>5} {'t_default':>9} {'t_ab13md':>9} "
           f"{'ratio':>6} {'peak ratio':>12} {'certified':>9}")
    out = [hdr, "-" * len(hdr)]
    for name, (_, t, up, sw), t_ab, ref, sys, S in entries:
        Mp = freqresp(sys, [sw.peak_frequency])[:, :, 0]
        c = dg_bound(Mp, S, sw.peak.Dl, sw.peak.Dr, sw.peak.G)
        ok = abs(c - sw.peak_upper) <= 1e-9 * sw.peak_upper
        blocks = " ".join(f"F{b.rows}x{b.cols}" if b.kind == "full" else
                          f"{'C' if b.kind == 'scalar' else 'r'}{b.rows}" for b in S.blocks)
        out.append(f"{name:<10} {blocks:<22} {S.nrows:>3} {up.size:>5} {t:9.3f} {t_ab:9.3f} {t / t_ab:6.2f} "
                   f"{up.max() / ref.max():12.9f} {'yes' if ok else 'NO':>9}")
    return "\n".join(out)


def ab13md_sweep(sys, omega, nb, it):
    """AB13MD's bound at each frequency (cold start) and the CPU seconds of it with the response."""
    from slycot import ab13md

    from mutext.lti import freqresp
    t0 = time.process_time()
    H = freqresp(sys, omega)
    ref = np.array([ab13md(H[:, :, k], nb, it)[0] for k in range(omega.size)])
    return ref, time.process_time() - t0


def build_lmi_once(S) -> None:
    """Build the LMI of ``S`` once, so that cvxpy's compile time falls outside the timings."""
    from mutext.mu import mu_upper
    mu_upper(np.eye(S.nrows), S, method="lmi")


def seeds_table(count: int, points: int) -> str:
    """One row per seed 0 .. count-1: AB13MD's CPU seconds, then for the default sweep and
    ``method="fast"`` their time ratio to it, the largest ratio of the bounds at one frequency and
    the number of frequencies more than 0.1 % above AB13MD; the last row sums them up."""
    from mutext.mu import mu_sweep
    omega = np.logspace(-2, 2, points)
    build_lmi_once(problem(0)[1])
    hdr = (f"{'seed':>4} {'t_ab13md':>8} {'auto t/t_ab':>11} {'auto max':>10} {'>1.001':>6} "
           f"{'fast t/t_ab':>11} {'fast max':>10} {'>1.001':>6}")
    out = [f"{points} frequencies per problem, blocks r1 r1 C2x2 C1 C1", hdr, "-" * len(hdr)]
    stats = {"auto": [], "fast": []}
    for seed in range(count):
        sys, S, nb, it = problem(seed)
        ref, t_ab = ab13md_sweep(sys, omega, nb, it)
        row = f"{seed:4d} {t_ab:8.3f}"
        for method in ("auto", "fast"):
            t0 = time.process_time()
            sw = mu_sweep(sys, S, omega, method=method, lower="none", refine=False)
            t = time.process_time() - t0
            r = sw.upper / ref
            stats[method].append((t / t_ab, r.max(), int(np.sum(r > 1.001))))
            row += f" {t / t_ab:11.2f} {r.max():10.6f} {stats[method][-1][2]:6d}"
        out.append(row)
    row = f"{'all':>4} {'':>8}"
    for method in ("auto", "fast"):
        ratio, worst, bad = zip(*stats[method])
        row += f" {np.mean(ratio):7.2f} av {max(worst):10.6f} {sum(bad):6d}"
    out.append(row)
    return "\n".join(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--points", type=int, default=500)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--lmi", action="store_true", help="also the LMI sweep (slow)")
    ap.add_argument("--seeds", type=int, default=0,
                    help="instead: the problems of seeds 0 .. SEEDS-1, one row each (auto and fast against AB13MD)")
    args = ap.parse_args(argv)
    if args.seeds > 0:
        print(seeds_table(args.seeds, args.points))
        return 0

    from mutext.lti import freqresp
    from mutext.mu import dg_bound, mu_sweep

    sys, S, nb, it = problem(args.seed)
    omega = np.logspace(-2, 2, args.points)
    build_lmi_once(S)
    ref, t_ab = ab13md_sweep(sys, omega, nb, it)

    rows = [("ab13md", t_ab, ref, None)]
    methods = ["auto", "fast", "osborne"] + (["lmi"] if args.lmi else [])
    for method in methods:
        t0 = time.process_time()
        sw = mu_sweep(sys, S, omega, method=method, lower="none", refine=False)
        rows.append((method, time.process_time() - t0, sw.upper, sw))

    print(f"10 states, 6x6, blocks r1 r1 C2x2 C1 C1, {omega.size} frequencies (seed {args.seed})")
    hdr = (f"{'method':<8} {'seconds':>8} {'peak':>13} {'t/t_ab13md':>10} {'peak/ab13md':>12} "
           f"{'median ratio':>12} {'max ratio':>10} {'>1.001':>6} {'peak cert':>10}")
    print(hdr)
    print("-" * len(hdr))
    for name, t, up, sw in rows:
        r = up / ref
        cert = ""
        if sw is not None and sw.peak is not None:
            Mp = freqresp(sys, [sw.peak_frequency])[:, :, 0]
            c = dg_bound(Mp, S, sw.peak.Dl, sw.peak.Dr, sw.peak.G)
            cert = f"{abs(c - sw.peak_upper) / sw.peak_upper:.1e}"
        print(f"{name:<8} {t:8.3f} {up.max():13.8f} {t / t_ab:10.2f} {up.max() / ref.max():12.8f} "
              f"{np.median(r):12.8f} {r.max():10.6f} {int(np.sum(r > 1.001)):6d} {cert:>10}")
    print()
    print(default_table([(f"{args.points} freq", rows[1], t_ab, ref, sys, S)]))
    fast = rows[2]
    print(f"fast vs AB13MD: time ratio {fast[1] / t_ab:.2f}, peak (fast - ab13md) / ab13md = "
          f"{(fast[2].max() - ref.max()) / ref.max():+.2e} "
          f"(peak checked by the LMI: {fast[3].peak.method}, no certificate found below "
          f"{fast[3].peak.lower_level:.8f})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
