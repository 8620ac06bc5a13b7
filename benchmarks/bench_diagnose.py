"""Diagnosis on data with hidden effects, through the batch engine: success rate, false alarms, size error,
time, and the speed-up with jobs.

For every example, noise level and seed, :func:`mutext.hide.hidden_effect_data`
writes a data set (``model.toml``, ``measured/``, ``validate/``,
``answer_key.json``; kind, place and size at random, about one case in six
with none) under a work directory, as ``mutext rig hide --count`` does.  The
cases are then diagnosed by :func:`mutext.batch.diagnose_batch` -- the path of
``mutext diagnose --batch DIR --jobs N``: one joblib task per data set, its
report written beside it, ``summary.csv`` -- once for every ``--jobs`` value
(default 1, then 2).  Printed:

* per jobs value: wall time of the batch, speed-up over the first value, the
  sum of the cases' own seconds (diagnosis and report; of which the diagnosis
  alone), and the **per-case pool overhead** ``(jobs x wall - sum of case seconds) / cases``: worker time
  per case not spent on a case (starting the workers and importing mutext in
  them, sending the tasks and results, idle workers at the end);
* the bare pool: cases that do nothing, through the same engine
  (:func:`mutext.batch.run_parallel`): start-up of fresh workers, then the
  cost per case;
* per example and noise level (from the first run; the verdicts of every run
  are compared): right -- kind and location of the verdict equal the key, over
  the cases with an effect; false alarms -- a finding on a "none" case; size
  error -- median |found - true| / |true| over the right cases, beside the
  error of the best possible fit, one told the true kind and location
  (``diagnose(..., only=...)``, also run through the engine; ``--no-told``
  skips it) and their ratio (target: at most 1.5); seconds per diagnosis
  (median and maximum, diagnosis alone).

Usage::

    python benchmarks/bench_diagnose.py                       # lumped chains, 3 noise levels, 12 seeds; jobs 1, 2
    python benchmarks/bench_diagnose.py --quick               # 2 examples x 3 seeds at 1 % noise (about a minute)
    python benchmarks/bench_diagnose.py --examples rotor --seeds 6 --noise 0.01
    python benchmarks/bench_diagnose.py --jobs 2              # one run, two workers
    python benchmarks/bench_diagnose.py --kind none --seeds 40  # false-alarm rate

Each case runs with one BLAS thread.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def _offset(key):
    """The 'no effect' value of a size (1 for a gain factor, 0 otherwise): size errors are relative to the change."""
    return 1.0 if key["kind"].endswith("gain") and key.get("unit") == "1" else 0.0


def told(folder: str) -> float | None:
    """Relative size error of the fit told the true kind and location (one task of the engine)."""
    from threadpoolctl import threadpool_limits

    from mutext.diagnose import diagnose
    d = Path(folder)
    key = json.loads((d / "answer_key.json").read_text())
    files = lambda sub: sorted(str(p) for p in (d / sub).iterdir())
    with threadpool_limits(1, "blas"):
        r = diagnose(str(d / "model.toml"), files("measured"), validate=files("validate"),
                     only=lambda h: (h.kind, h.station, h.element) == (key["kind"], key["station"], key["element"]))
    f = next((x for x in r.findings if x.kind != "none"), None)
    if f is None:
        return None
    return abs(f.value - key["value"]) / abs(key["value"] - _offset(key))


def noop(i):
    """A case that does nothing: what the pool itself costs."""
    return i


def write_cases(root: Path, examples, noises, seeds, kind):
    from mutext.hide import hidden_effect_data
    cases = []
    for e in examples:
        for n in noises:
            for s in seeds:
                d = root / f"{e}_n{n:g}_s{s}"
                hidden_effect_data(e, seed=s, noise=n, kind=kind, out_dir=d)
                cases.append((e, n, s, d))
    return cases


def case_result(row, example, noise, seed):
    """One case from its summary row, its answer key and its diagnosis.json."""
    d = Path(row["data_set"])
    key = json.loads((d / "answer_key.json").read_text())
    out = {"example": example, "seed": seed, "noise": noise, "kind": key["kind"], "station": key["station"],
           "folder": str(d)}
    if row["status"] != "ok":
        out["error"] = row.get("error", "failed")
        return out
    rep = json.loads((d / "diagnosis" / "diagnosis.json").read_text())
    out.update(found_kind=row["kind"], found_station=row["station"], right=bool(row.get("found")),
               seconds=rep.get("seconds", row["seconds"]), case_seconds=row["seconds"], gain=row["gain"],
               size_err=None, told_err=None, within_4std=None,
               ambiguous=[(a.get("kind"), a.get("station")) for a in rep.get("ambiguous_with") or []])
    if key["kind"] != "none" and out["right"]:
        out["size_err"] = abs(row["value"] - key["value"]) / abs(key["value"] - _offset(key))
        out["within_4std"] = abs(row["value"] - key["value"]) <= 4 * row["std"]
    return out


def bare_pool(jobs: int, n: int = 200):
    """(start-up of fresh workers [s], seconds per no-op case with warm workers) through mutext.batch."""
    from mutext.batch import run_parallel
    try:
        from joblib.externals.loky import get_reusable_executor
        get_reusable_executor().shutdown(wait=True)
    except Exception as exc:   # noqa: BLE001 - another backend: no pool to restart
        print(f"(pool not restarted: {exc})", file=sys.stderr)
    t0 = time.perf_counter()
    list(run_parallel(noop, [(i,) for i in range(jobs)], jobs=jobs))
    start = time.perf_counter() - t0
    t0 = time.perf_counter()
    list(run_parallel(noop, [(i,) for i in range(n)], jobs=jobs))
    return start, (time.perf_counter() - t0) / n


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--examples", nargs="+", default=None)
    p.add_argument("--noise", nargs="+", type=float, default=None)
    p.add_argument("--seeds", type=int, default=None, help="seeds per example and noise level (default 12)")
    p.add_argument("--first-seed", type=int, default=100)
    p.add_argument("--jobs", nargs="+", type=int, default=[1, 2],
                   help="run the whole batch once per value (default: 1 2)")
    p.add_argument("--kind", default=None, help="hide only this kind (e.g. none, for the false-alarm rate)")
    p.add_argument("--quick", action="store_true",
                   help="few cases: three_mass and four_story, 1 %% noise, 3 seeds (defaults of the options "
                        "above that are not given)")
    p.add_argument("--no-told", action="store_true", help="skip the fits told the true kind and location")
    p.add_argument("--keep", metavar="DIR", help="write the data sets, reports and summary.csv into DIR and keep them")
    args = p.parse_args(argv)
    examples = args.examples or ["three_mass", "four_story"]
    noises = args.noise or ([0.01] if args.quick else [0.003, 0.01, 0.03])
    seeds = range(args.first_seed, args.first_seed + (args.seeds or (3 if args.quick else 12)))
    if any(j == 0 for j in args.jobs):
        p.error("--jobs values must be positive (or -1 for all cores)")

    from mutext.batch import diagnose_batch, run_parallel
    from mutext.progress import ProgressLine
    root = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="bench-diagnose-"))
    root.mkdir(parents=True, exist_ok=True)
    try:
        cases = write_cases(root, examples, noises, seeds, args.kind)
        by_folder = {str(d): (e, n, s) for e, n, s, d in cases}
        load = os.getloadavg()[0] if hasattr(os, "getloadavg") else math.nan
        print(f"mutext diagnose --batch on hidden effects: {len(cases)} cases ({', '.join(examples)}; noise "
              f"{', '.join(f'{100 * n:g} %' for n in noises)}; {len(seeds)} seeds), {os.cpu_count()} cores, "
              f"load average {load:.1f} at the start")
        print()
        runs = []
        for jobs in args.jobs:
            t0 = time.perf_counter()
            rows = diagnose_batch(root, jobs=jobs, progress=ProgressLine())
            wall = time.perf_counter() - t0
            workers = os.cpu_count() if jobs < 0 else jobs
            busy = sum(r["seconds"] for r in rows)
            # each run overwrites the reports: read this run's diagnosis.json files now
            results = [case_result(r, *by_folder[r["data_set"]]) for r in rows]
            runs.append((jobs, wall, busy, (workers * wall - busy) / len(rows), results))
        print("| jobs | wall s | speed-up | sum of case s | of which diagnosis s | pool overhead per case s |")
        print("|---|---|---|---|---|---|")
        for jobs, wall, busy, over, res in runs:
            diag = sum(r["seconds"] for r in res if "error" not in r)
            print(f"| {jobs} | {wall:.1f} | {runs[0][1] / wall:.2f} | {busy:.1f} | {diag:.1f} | {over:.3f} |")
        pool_jobs = max(args.jobs)
        if pool_jobs != 1:
            start, per = bare_pool(pool_jobs)
            print(f"\nbare pool (no-op cases through mutext.batch.run_parallel, {pool_jobs} workers): start-up "
                  f"{start:.2f} s, then {1e3 * per:.2f} ms per case")
        verdicts = [[(r.get("found_kind"), r.get("found_station")) for r in res] for *_, res in runs]
        if len(runs) > 1:
            same = all(v == verdicts[0] for v in verdicts[1:])
            print(f"verdicts of the {len(runs)} runs identical: {'yes' if same else 'NO'}")
        results = runs[0][4]
        print(f"\nquality and seconds per diagnosis from the run with {runs[0][0]} job(s)")
        if not args.no_told:
            todo = [r for r in results if "error" not in r and r["kind"] != "none" and r["right"]]
            print(f"\nfits told the true kind and location: {len(todo)} cases", file=sys.stderr)
            for r, err in zip(todo, run_parallel(told, [(r["folder"],) for r in todo], jobs=pool_jobs,
                                                 progress=ProgressLine())):
                r["told_err"] = err
        report(results, examples, noises)
    finally:
        if not args.keep:
            shutil.rmtree(root, ignore_errors=True)


def report(results, examples, noises):
    print()
    print("| example | noise | cases | right (kind, place) | false alarms on 'none' | median size error "
          "| told kind+place | ratio | within 4 std | s median | s max |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for e in examples:
        for n in noises:
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
