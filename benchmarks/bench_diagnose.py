"""Diagnosis on data with hidden effects: success rate, false alarms, size error, time.

For every example, noise level and seed, :func:`mutext.hide.hidden_effect_data`
hides an effect (kind, place and size at random; about one case in six has
none) and :func:`mutext.diagnose.diagnose` is given the engineering model and
the data.  Printed per example and noise level:

* right: kind and location of the verdict equal the key, over the cases with an effect;
* false alarms: a finding on a "none" case;
* size error: median |found - true| / |true| over the right cases, beside the
  error of the best possible fit -- one told the true kind and location
  (``diagnose(..., only=...)``) -- and their ratio (target: at most 1.5);
* seconds per diagnosis (median and maximum).

Usage::

    python benchmarks/bench_diagnose.py                       # lumped chains, 3 noise levels, 12 seeds
    python benchmarks/bench_diagnose.py --examples rotor --seeds 6 --noise 0.01
    python benchmarks/bench_diagnose.py --jobs 2              # one process per case
    python benchmarks/bench_diagnose.py --kind none --seeds 40  # false-alarm rate

Cases run in parallel processes (``--jobs``), each with one BLAS thread.
"""
from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time
from concurrent.futures import ProcessPoolExecutor

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def one(example, seed, noise, kind=None):
    from mutext.diagnose import diagnose
    from mutext.hide import hidden_effect_data
    case = hidden_effect_data(example, seed=seed, noise=noise, kind=kind)
    key = case.key
    t0 = time.perf_counter()
    d = diagnose(case.model, case.measured, validate=case.validate)
    sec = time.perf_counter() - t0
    v = d.verdict
    out = {"example": example, "seed": seed, "noise": noise, "kind": key["kind"], "station": key["station"],
           "found_kind": v.kind, "found_station": v.station, "right": (v.kind, v.station) == (key["kind"],
                                                                                          key["station"]),
           "seconds": sec, "gain": d.gain, "size_err": None, "told_err": None, "within_4std": None,
           "ambiguous": [(a.kind, a.station) for a in d.ambiguous_with]}
    if key["kind"] != "none" and out["right"]:
        out["size_err"] = abs(v.value - key["value"]) / abs(key["value"] - (1.0 if key["unit"] == "1"
                                                                            and key["kind"].endswith("gain")
                                                                            else 0.0))
        out["within_4std"] = abs(v.value - key["value"]) <= 4 * v.std
        told = diagnose(case.model, case.measured, validate=case.validate,
                        only=lambda h: (h.kind, h.station, h.element) == (key["kind"], key["station"],
                                                                          key["element"]))
        f = next(x for x in told.findings if x.kind != "none")
        out["told_err"] = abs(f.value - key["value"]) / abs(key["value"] - (1.0 if key["kind"].endswith("gain")
                                                                          else 0.0))
    return out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--examples", nargs="+", default=["three_mass", "four_story"])
    p.add_argument("--noise", nargs="+", type=float, default=[0.003, 0.01, 0.03])
    p.add_argument("--seeds", type=int, default=12, help="seeds per example and noise level")
    p.add_argument("--first-seed", type=int, default=100)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--kind", default=None, help="hide only this kind (e.g. none, for the false-alarm rate)")
    args = p.parse_args(argv)
    jobs = [(e, s, n) for e in args.examples for n in args.noise
            for s in range(args.first_seed, args.first_seed + args.seeds)]
    t0 = time.perf_counter()
    results = []
    with ProcessPoolExecutor(max_workers=args.jobs) as ex:
        futs = [ex.submit(one, *j, args.kind) for j in jobs]
        for k, f in enumerate(futs, 1):
            try:
                results.append(f.result())
            except Exception as exc:       # a failing case is a result too
                e, s, n = jobs[k - 1]
                results.append({"example": e, "seed": s, "noise": n, "error": repr(exc)})
            print(f"\r{k}/{len(jobs)} cases", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    print(f"mutext diagnose on hidden effects ({len(jobs)} cases, {args.jobs} processes, "
          f"{time.perf_counter() - t0:.0f} s wall)")
    print()
    print("| example | noise | cases | right (kind, place) | false alarms on 'none' | median size error "
          "| told kind+place | ratio | within 4 std | s median | s max |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for e in args.examples:
        for n in args.noise:
            rs = [r for r in results if r["example"] == e and r["noise"] == n]
            errs = [r for r in rs if "error" in r]
            ok = [r for r in rs if "error" not in r]
            eff = [r for r in ok if r["kind"] != "none"]
            none = [r for r in ok if r["kind"] == "none"]
            right = [r for r in eff if r["right"]]
            fa = [r for r in none if not r["right"]]
            se = [r["size_err"] for r in right if r["size_err"] is not None]
            te = [r["told_err"] for r in right if r["told_err"] is not None]
            w4 = [r["within_4std"] for r in right if r["within_4std"] is not None]
            med = statistics.median(se) if se else math.nan
            medt = statistics.median(te) if te else math.nan
            secs = [r["seconds"] for r in ok]
            print(f"| {e} | {100 * n:g} % | {len(rs)}{f' ({len(errs)} errors)' if errs else ''} | "
                  f"{len(right)}/{len(eff)} | {len(fa)}/{len(none)} | {100 * med:.3g} % | {100 * medt:.3g} % | "
                  f"{med / medt if medt > 0 else math.nan:.2f} | {sum(w4)}/{len(w4)} | "
                  f"{statistics.median(secs) if secs else math.nan:.1f} | {max(secs) if secs else math.nan:.1f} |")
    wrong = [r for r in results if "error" not in r and not r["right"]]
    if wrong:
        print("\nmissed:")
        for r in wrong:
            print(f"  {r['example']} seed {r['seed']} noise {r['noise']}: key {r['kind']} at {r['station']}, "
                  f"found {r['found_kind']} at {r['found_station']}; ambiguous with {r['ambiguous']}")
    for r in results:
        if "error" in r:
            print(f"  error: {r['example']} seed {r['seed']} noise {r['noise']}: {r['error']}")


if __name__ == "__main__":
    main()
