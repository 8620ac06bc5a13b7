"""Diagnosis in an open world: effects inside and outside the hypothesis library, two at once, none.

``bench_diagnose.py`` measures the diagnosis on data that hold one effect its
library has a hypothesis for.  Here the data come from a generator written
apart from the code under test (``benchmarks/_open_world.py``: plain TOML,
numpy matrices, a direct complex solve, its own noise) and hold, for the
lumped chains ``three_mass`` and ``four_story``:

* ``in_library``: one effect of every in-library kind (spring changed,
  grounded spring added, mass changed, damper changed, grounded damper added,
  sensor gain, exciter gain, sensor delay, a unit slipped in one measured
  file: the library's ``channel_scale`` of that file), and a tuned-mass
  absorber and a stiffness loss shared by every spring (the generator's
  out-of-library ``tuned_absorber`` and ``stiffness_loss``, scored here as
  the library's ``absorber`` at its host mass and ``distributed_stiffness``
  over the run of all springs: :data:`NOW_IN_LIBRARY`);
* ``two_effect``: two in-library effects at different elements, each
  detectable alone;
* ``out_of_library``: effects no single hypothesis describes (proportional
  damping, a scaled frequency axis, a roving sensor mass, a cubic spring,
  a spring between non-adjacent masses, a wrong model), each enlarged until
  the best single library hypothesis leaves at least the noise's own misfit;
* ``none``: no effect.

Every case is diagnosed with ``mutext.diagnose.diagnose(case.model_path,
case.measured, validate=case.validate)`` (one BLAS thread per process).

Definitions
-----------
The result is read through the three-outcome API, with fallbacks for
versions without it:

* ``d.status``: "explained", "partly explained" or "not explained"
  (fallback: "explained" when ``d.verdict.significant`` or the verdict's kind
  is "none", else "not explained");
* ``d.effects``: the accepted findings in order (fallback: ``[d.verdict]``
  unless its kind is "none"); a finding has ``kind``, ``station``,
  ``element``, ``value``, ``std``, ``unit`` and ``at_bound`` (fallback False).

An explanation is judged by what it claims, not by its labels: the
generator applies the claimed effects (``d.effects``: kind, station, element,
value) to its own matrices and measurement chain of the model handed over
(``_open_world.claimed_data``) and compares the noise-free responses with the
true noise-free data (``_open_world.equivalence_error``): the rms of
:math:`|\ln(H_{\mathrm{claimed}}/H_{\mathrm{true}})|` over the validation
channels and over the measured files (where a file's own scale shows), the
larger of the two.  Below ``noise / 3`` (:data:`_open_world.EQUIVALENT`) the
claimed system reproduces the true one to a third of the noise at every point
(its added mean-square error at most a ninth of the noise's, on channels and
frequencies never fitted too): an equivalent description of the data, not a
wrong cause.  Some out-of-library effects are exactly such combinations on
some chains: proportional damping :math:`C \to (1 + a) C` on a chain of
discrete dampers is every damper changed by the fraction a, a distributed
stiffness loss every spring changed by -8 %.

Per case:

* **right**: status "explained" and the (kind, station) pairs of
  ``d.effects`` equal those of the key, as a multiset (a two-effect case
  needs both, found as two effects); for a "none" case: "explained" with no
  effect.  Out-of-library cases have no right answer of this form ("-").
* **right (equivalent)**: status "explained", not right as above, and the
  claimed system equivalent to the true one (in-library, two-effect and
  out-of-library cases; not for "none": an effect there is a false alarm).
* **right but flagged**: the right effects with status "partly explained"
  (counted as honest too).
* **honest**: status "partly explained" or "not explained".
* **confidently wrong**: status "explained", neither right nor equivalent
  (for out-of-library cases: every "explained" whose claimed system is not
  equivalent, with an effect or with none).
* **false alarm**: on a "none" case, any effect reported (whatever the status).
* **size error**: ``|found - true| / |true change|`` (gains: the change of the
  factor from 1; a file's scale: ``|found / true - 1|``) over the right
  single-effect (in-library) cases; beside it the same for the fit told the
  true kind and place (``diagnose(..., only=lambda h: (h.kind, h.station,
  h.element) == key)``), over the same cases; their ratio should stay near 1.
* **seconds**: ``d.seconds`` of the diagnosis (median, max).

Goals (printed with the totals): in-library >= 95 % right (exact or
equivalent), two-effect >= 90 % right (exact or equivalent), out-of-library 0
confidently wrong, false alarms <= 2 %.

Usage::

    python benchmarks/bench_diagnose_open.py                   # 1 % noise, 202 cases (5 seeds), about 25 min/job
    python benchmarks/bench_diagnose_open.py --quick           # a handful of cases (about a minute)
    python benchmarks/bench_diagnose_open.py --noise 0.003 0.01 0.03 --jobs 2 --json rows.json
    python benchmarks/bench_diagnose_open.py --categories out_of_library --seeds 2

Counts per example and noise level with ``--seeds S`` (default 5): in-library S
per kind (11 kinds: the generator's 9 and :data:`NOW_IN_LIBRARY`), two-effect 3 S,
out-of-library ceil(0.6 S) per kind (7 kinds), none 2 S.  With S = 5 and both
examples: 110 in-library, 30 two-effect, 42 out-of-library and 20 none cases per
noise level.
"""
from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import argparse
import json
import math
import shutil
import statistics
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

HERE = Path(__file__).resolve().parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

from _open_world import CATEGORIES as GENERATOR_CATEGORIES  # noqa: E402
from _open_world import EQUIVALENT  # noqa: E402

#: Kinds the generator draws as out of library that the diagnosis now has a hypothesis for: scored as
#: in-library (key: the package's kind at the host mass, sized by the generator's drawn value).
NOW_IN_LIBRARY = {"tuned_absorber": "absorber", "stiffness_loss": "distributed_stiffness"}
CATEGORIES = dict(GENERATOR_CATEGORIES)
CATEGORIES["in_library"] = tuple(GENERATOR_CATEGORIES["in_library"]) + tuple(NOW_IN_LIBRARY)
CATEGORIES["out_of_library"] = tuple(k for k in GENERATOR_CATEGORIES["out_of_library"] if k not in NOW_IN_LIBRARY)

GOALS = {"in_library": 0.95, "two_effect": 0.90, "out_of_library": 0, "false_alarms": 0.02}
QUICK = {"in_library": ("spring_change", "sensor_delay", "unit_slip", "tuned_absorber"), "two_effect": ("pair",),
         "out_of_library": ("rayleigh_damping", "cubic_spring", "nonadjacent_spring"), "none": ("none",)}


def case_list(examples, noises, seeds: int, first: int, categories, quick: bool):
    """(example, category, kind, seed, noise) of every case."""
    out = []
    for n in noises:
        for e in examples:
            for cat in categories:
                kinds = QUICK[cat] if quick else CATEGORIES[cat]
                per = 1 if quick else {"in_library": seeds, "two_effect": 3 * seeds,
                                       "out_of_library": math.ceil(0.6 * seeds), "none": 2 * seeds}[cat]
                for k in kinds:
                    for s in range(first, first + per):
                        out.append((e, cat, k, s, n))
    return out


# ----------------------------------------------------------------------------------------------
# reading a diagnosis (the three-outcome API, with fallbacks)
# ----------------------------------------------------------------------------------------------

def status_of(d) -> str:
    s = getattr(d, "status", None)
    if s is not None:
        return str(s)
    v = d.verdict
    return "explained" if (v.significant or v.kind == "none") else "not explained"


def effects_of(d) -> list:
    eff = getattr(d, "effects", None)
    if eff is not None:
        return [f for f in eff if f.kind != "none"]
    return [] if d.verdict.kind == "none" else [d.verdict]


def finding_row(f) -> dict:
    return {"kind": f.kind, "station": f.station, "element": f.element, "value": float(f.value),
            "std": float(getattr(f, "std", math.nan)), "unit": getattr(f, "unit", ""),
            "at_bound": bool(getattr(f, "at_bound", False)),
            **({"values": [float(x) for x in f.values]} if getattr(f, "values", None) is not None else {}),
            **({"run": list(f.hypothesis.run)} if getattr(getattr(f, "hypothesis", None), "run", ()) else {})}


def size_error(e: dict, f) -> float:
    """|found - true| / |true change| (gains: the change from 1; a file's scale: |found / true - 1|)."""
    v = float(f["value"] if isinstance(f, dict) else f.value)
    if e["kind"] == "channel_scale":
        return abs(v / e["value"] - 1)
    null = 1.0 if e["kind"].endswith("gain") else 0.0
    return abs(v - e["value"]) / abs(e["value"] - null)


def score(row: dict) -> dict:
    """right, right_equiv, right_flagged, honest, confidently_wrong, false_alarm, size_err of one case."""
    cat, st = row["category"], row["status"]
    key = sorted(((e["kind"], e["station"]) for e in row["key_effects"]), key=str)
    found = sorted(((f["kind"], f["station"]) for f in row["found"]), key=str)
    honest = st in ("partly explained", "not explained")
    explained = st == "explained"
    eq = row.get("equiv")
    equivalent = eq is not None and eq["error"] < EQUIVALENT * row["noise"]
    out = {"honest": honest, "right": None, "right_equiv": False, "right_flagged": False,
           "confidently_wrong": False, "false_alarm": None, "size_err": None}
    if cat == "out_of_library":
        out["right_equiv"] = explained and equivalent
        out["confidently_wrong"] = explained and not equivalent
        return out
    match = found == key
    out["right"] = explained and match
    out["right_equiv"] = explained and not match and equivalent and cat != "none"
    out["right_flagged"] = st == "partly explained" and match and bool(key)
    out["confidently_wrong"] = explained and not match and not out["right_equiv"]
    if cat == "none":
        out["false_alarm"] = bool(found)
    if out["right"] and cat == "in_library":
        out["size_err"] = size_error(row["key_effects"][0], row["found"][0])
    return out


def right_any(r) -> bool:
    """Right, exactly or by an equivalent explanation."""
    return bool(r.get("right")) or bool(r.get("right_equiv"))


# ----------------------------------------------------------------------------------------------
# one case (a joblib task)
# ----------------------------------------------------------------------------------------------

def run_case(example, category, kind, seed, noise, workdir, told=True) -> dict:
    """Generate one case, diagnose it (and, for a single in-library effect, fit it told kind and place)."""
    if str(HERE) not in sys.path:
        sys.path.insert(0, str(HERE))
    from threadpoolctl import threadpool_limits

    from _open_world import equivalence_error, make_case
    from mutext.diagnose import diagnose
    row = {"example": example, "category": category, "kind": kind, "seed": seed, "noise": noise}
    try:
        t0 = time.perf_counter()
        now_in = category == "in_library" and kind in NOW_IN_LIBRARY
        case = make_case(example, "out_of_library" if now_in else category, kind, seed, noise, workdir=workdir)
        row["gen_seconds"] = time.perf_counter() - t0
        row["key"] = case.key
        row["key_effects"] = case.key["effects"]
        if now_in:
            det = case.key["details"]
            if kind == "tuned_absorber":
                e = {"station": det["station"], "element": f"absorber_{det['mass']}", "value": det["value"],
                     "unit": "kg"}
            else:       # every spring times (1 - d): the run of all springs (in chain order) changed by -d
                from _open_world import read_chain
                names = [s["name"] for s in read_chain(case.model_path).springs]
                e = {"station": 1, "element": f"{names[0]}..{names[-1]}", "value": -det["value"], "unit": "1"}
            row["key_effects"] = [{"kind": NOW_IN_LIBRARY[kind], **e}]
        with threadpool_limits(1, "blas"):
            d = diagnose(case.model_path, case.measured, validate=case.validate)
            v = getattr(d, "verdict", None)
            row.update(status=status_of(d), found=[finding_row(f) for f in effects_of(d)],
                       seconds=float(d.seconds), gain=float(getattr(d, "gain", math.nan)),
                       verdict=None if v is None else finding_row(v) | {"significant": bool(v.significant)},
                       notes=[str(x) for x in getattr(d, "notes", [])])
            try:
                eq = equivalence_error(case, row["found"])
                row["equiv"] = eq | {"in_noise": eq["error"] / noise}
            except (ValueError, StopIteration) as exc:      # a claim the generator has no physics for
                row["equiv"], row["equiv_error"] = None, repr(exc)
            row.update(score(row))
            row["told_err"] = None
            if told and category == "in_library":
                e = row["key_effects"][0]
                want = (e["kind"], e["station"], e["element"])
                try:
                    dt = diagnose(case.model_path, case.measured, validate=case.validate,
                                  only=lambda h: (h.kind, h.station, h.element) == want)
                    fs = getattr(dt, "findings", None) or effects_of(dt)
                    f = next((x for x in fs if x.kind != "none"), None)
                    if f is not None:
                        row["told_err"] = size_error(e, f)
                except Exception as exc:     # noqa: BLE001 - the told fit is a reference, not the benchmark
                    row["told_error"] = repr(exc)
    except Exception as exc:                 # noqa: BLE001 - reported as a row with an error
        row["error"] = f"{type(exc).__name__}: {exc}"
    return row


# ----------------------------------------------------------------------------------------------
# the tables
# ----------------------------------------------------------------------------------------------

def _pct(a, b):
    return f"{a}/{b}" + (f" ({100 * a / b:.0f} %)" if b else "")


def _med(xs):
    xs = [x for x in xs if x is not None]
    return statistics.median(xs) if xs else math.nan


def table(rows, title):
    print(f"\n### {title}\n")
    print("| category | cases | right | right (equivalent) | right but flagged | honest (partly/not explained) "
          "| confidently wrong | false alarms | median size error | told kind+place | ratio | s median | s max |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for cat in CATEGORIES:
        rs = [r for r in rows if r["category"] == cat]
        if not rs:
            continue
        ok = [r for r in rs if "error" not in r]
        errs = len(rs) - len(ok)
        right = "-" if cat == "out_of_library" else _pct(sum(bool(r["right"]) for r in ok), len(ok))
        equiv = "-" if cat == "none" else _pct(sum(bool(r["right_equiv"]) for r in ok), len(ok))
        flagged = "-" if cat in ("out_of_library", "none") else str(sum(r["right_flagged"] for r in ok))
        fa = _pct(sum(bool(r["false_alarm"]) for r in ok), len(ok)) if cat == "none" else "-"
        right_rows = [r for r in ok if r.get("right")]
        se = _med([r["size_err"] for r in right_rows])
        te = _med([r.get("told_err") for r in right_rows if r["size_err"] is not None])
        secs = [r["seconds"] for r in ok]
        size = "-" if cat != "in_library" else f"{100 * se:.3g} %"
        told = "-" if cat != "in_library" else f"{100 * te:.3g} %"
        ratio = "-" if cat != "in_library" else f"{se / te:.2f}" if te and te > 0 else "nan"
        print(f"| {cat} | {len(rs)}{f' ({errs} errors)' if errs else ''} | {right} | {equiv} | {flagged} | "
              f"{_pct(sum(r['honest'] for r in ok), len(ok))} | "
              f"{_pct(sum(r['confidently_wrong'] for r in ok), len(ok))} | {fa} | {size} | {told} | {ratio} | "
              f"{_med(secs):.1f} | {max(secs) if secs else math.nan:.1f} |")


def _claims(r) -> str:
    return ", ".join(f"{f['kind']}@{f['station']}" for f in r["found"]) or "nothing"


def _eq(r) -> str:
    eq = r.get("equiv")
    return "n/a" if eq is None else f"{eq['in_noise']:.3g}"


_STATUS = {"explained": "E", "partly explained": "P", "not explained": "N"}


def kind_table(rows):
    """Per kind of the categories with a right answer (in-library, two-effect, none)."""
    print("\n| category | kind | cases | right | right (equivalent) | right but flagged | honest | confidently wrong "
          "| claimed when confidently wrong |")
    print("|---|---|---|---|---|---|---|---|---|")
    for cat, kinds in CATEGORIES.items():
        if cat == "out_of_library":
            continue
        for k in kinds:
            rs = [r for r in rows if r["category"] == cat and r["kind"] == k and "error" not in r]
            if not rs:
                continue
            wrong = Counter(_claims(r) for r in rs if r["confidently_wrong"])
            print(f"| {cat} | {k} | {len(rs)} | {sum(bool(r['right']) for r in rs)} | "
                  f"{sum(bool(r['right_equiv']) for r in rs)} | {sum(bool(r['right_flagged']) for r in rs)} | "
                  f"{sum(r['honest'] for r in rs)} | {sum(r['confidently_wrong'] for r in rs)} | "
                  f"{'; '.join(f'{w} x{c}' for w, c in wrong.most_common(4))} |")


def open_kind_table(rows):
    """Per out-of-library kind: how each was answered (statuses E explained, P partly, N not explained) and,
    when explained, what was claimed and how far its system is from the true one (in noise units)."""
    rs0 = [r for r in rows if r["category"] == "out_of_library" and "error" not in r]
    if not rs0:
        return
    print(f"\nout of library, per kind (statuses: E explained, P partly explained, N not explained; equivalence "
          f"error: rms |ln(H_claimed/H_true)| / noise, equivalent below {EQUIVALENT:.3g}):\n")
    print("| kind | cases | honest | right (equivalent) | confidently wrong | statuses | explained as (equivalence "
          "error) |")
    print("|---|---|---|---|---|---|---|")
    for k in CATEGORIES["out_of_library"]:
        rs = [r for r in rs0 if r["kind"] == k]
        if not rs:
            continue
        st = Counter(_STATUS.get(r["status"], r["status"]) for r in rs)
        stx = " ".join(f"{s}{st[s]}" for s in ("E", "P", "N") if st[s])
        expl = "; ".join(f"{r['example']} s{r['seed']}: {_claims(r)} ({_eq(r)})" for r in rs
                         if r["status"] == "explained")
        print(f"| {k} | {len(rs)} | {sum(r['honest'] for r in rs)} | {sum(bool(r['right_equiv']) for r in rs)} | "
              f"{sum(r['confidently_wrong'] for r in rs)} | {stx} | {expl or '-'} |")


def _found_text(r) -> str:
    return "; ".join(f"{f['kind']}@{f['station']} ({f['element']} {f['value']:.4g} +/- {f['std']:.2g}"
                     f"{', at bound' if f['at_bound'] else ''})" for f in r["found"]) or "nothing"


def _key_text(r) -> str:
    return "; ".join(f"{e['kind']}@{e['station']} ({e['element']} {e['value']:.4g})" for e in r["key_effects"]) \
        or r["key"]["description"]


def misses(rows):
    ok = [r for r in rows if "error" not in r]
    cw = [r for r in ok if r["confidently_wrong"]]
    if cw:
        print("\nconfidently wrong (status explained, claimed system not equivalent to the true one):")
    for r in cw:
        sf = r["key"].get("single_fit") or {}
        best = f" [best single hypothesis leaves {sf['misfit']:.3g} x noise]" if sf else ""
        print(f"  {r['example']} {r['category']}/{r['kind']} seed {r['seed']} noise {r['noise']:g}: "
              f"{r['status']}: {_found_text(r)}; truth {_key_text(r)}{best}; equivalence error {_eq(r)} x noise")
    eqs = [r for r in ok if r["right_equiv"]]
    if eqs:
        print("\nright by an equivalent explanation:")
    for r in eqs:
        print(f"  {r['example']} {r['category']}/{r['kind']} seed {r['seed']} noise {r['noise']:g}: "
              f"{_found_text(r)}; truth {_key_text(r)}; equivalence error {_eq(r)} x noise")
    hon = [r for r in ok if r["category"] in ("in_library", "two_effect", "none") and not right_any(r)
           and not r["confidently_wrong"]]
    if hon:
        print("\nnot right but honest (in-library, two-effect, none):")
    for r in hon:
        print(f"  {r['example']} {r['category']}/{r['kind']} seed {r['seed']} noise {r['noise']:g}: "
              f"key {_key_text(r)}; {r['status']}: {_found_text(r)} (equivalence error {_eq(r)} x noise)")
    for r in rows:
        if "error" in r:
            print(f"  error: {r['example']} {r['category']}/{r['kind']} seed {r['seed']} noise {r['noise']:g}: "
                  f"{r['error']}")


def goals(rows):
    ok = [r for r in rows if "error" not in r]
    print("\n### totals and goals\n")
    lines = []
    for cat in ("in_library", "two_effect"):
        rs = [r for r in ok if r["category"] == cat]
        if rs:
            n = sum(right_any(r) for r in rs)
            lines.append((f"{cat} right (exact or equivalent)", _pct(n, len(rs)), f">= {100 * GOALS[cat]:.0f} %",
                          n / len(rs) >= GOALS[cat]))
    rs = [r for r in ok if r["category"] == "out_of_library"]
    if rs:
        n = sum(r["confidently_wrong"] for r in rs)
        lines.append(("out_of_library confidently wrong", _pct(n, len(rs)), "0", n == 0))
    rs = [r for r in ok if r["category"] == "none"]
    if rs:
        n = sum(bool(r["false_alarm"]) for r in rs)
        lines.append(("false alarms on none", _pct(n, len(rs)), f"<= {100 * GOALS['false_alarms']:.0f} %",
                      n / len(rs) <= GOALS["false_alarms"]))
    cw = [r for r in ok if r["category"] != "out_of_library" and r["confidently_wrong"]]
    lines.append(("confidently wrong, other categories", _pct(len(cw), len([r for r in ok
                                                                          if r["category"] != "out_of_library"])),
                  "(no goal)", None))
    print("| measure | measured | goal | met |")
    print("|---|---|---|---|")
    for name, got, goal, met in lines:
        print(f"| {name} | {got} | {goal} | {'-' if met is None else 'yes' if met else 'NO'} |")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--noise", nargs="+", type=float, default=[0.01])
    p.add_argument("--examples", nargs="+", default=["three_mass", "four_story"],
                   choices=["three_mass", "four_story"])
    p.add_argument("--categories", nargs="+", default=list(CATEGORIES), choices=list(CATEGORIES))
    p.add_argument("--seeds", type=int, default=5, help="scale of the case counts (see the docstring; default 5)")
    p.add_argument("--first-seed", type=int, default=1000)
    p.add_argument("--quick", action="store_true", help="a handful of cases: 8 per example and noise level")
    p.add_argument("--jobs", type=int, default=1, help="joblib workers (-1: all cores)")
    p.add_argument("--no-told", action="store_true", help="skip the fits told the true kind and place")
    p.add_argument("--json", metavar="OUT", help="write the per-case rows to OUT")
    p.add_argument("--keep", metavar="DIR", help="write model files of the wrong-model cases into DIR and keep them")
    args = p.parse_args(argv)
    if args.seeds < 1 or args.jobs == 0:
        p.error("--seeds must be >= 1 and --jobs nonzero")
    cases = case_list(args.examples, args.noise, args.seeds, args.first_seed, args.categories, args.quick)
    root = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="bench-open-"))
    root.mkdir(parents=True, exist_ok=True)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else math.nan
    counts = Counter(c[1] for c in cases)
    print(f"mutext diagnose on open-world data (benchmarks/_open_world.py): {len(cases)} cases "
          f"({', '.join(f'{counts[c]} {c}' for c in CATEGORIES if counts[c])}; {', '.join(args.examples)}; noise "
          f"{', '.join(f'{100 * n:g} %' for n in args.noise)}), {args.jobs} job(s), {os.cpu_count()} cores, "
          f"load average {load:.1f} at the start")
    import mutext
    import mutext.diagnose as md
    api = "three-outcome status" if hasattr(md.Diagnosis, "status") else "verdict only (status by fallback)"
    print(f"mutext {mutext.__version__} from {Path(mutext.__file__).parent}; result API: {api}")
    t0 = time.perf_counter()
    rows = []
    try:
        if args.jobs == 1:
            it = (run_case(*c, str(root), not args.no_told) for c in cases)
        else:
            from joblib import Parallel, delayed
            it = Parallel(n_jobs=args.jobs, return_as="generator")(
                delayed(run_case)(*c, str(root), not args.no_told) for c in cases)
        for k, row in enumerate(it, 1):
            rows.append(row)
            tag = row.get("status", row.get("error", "?"))
            print(f"\r[{k}/{len(cases)}] {time.perf_counter() - t0:6.0f} s  {row['example']} {row['kind']} "
                  f"seed {row['seed']}: {tag[:40]:40s}", end="", file=sys.stderr, flush=True)
        print(file=sys.stderr)
    finally:
        if not args.keep:
            shutil.rmtree(root, ignore_errors=True)
    wall = time.perf_counter() - t0
    print(f"wall time {wall:.0f} s")
    for n in args.noise:
        rs = [r for r in rows if r["noise"] == n]
        table(rs, f"noise {100 * n:g} %")
        kind_table(rs)
        open_kind_table(rs)
    if len(args.noise) > 1:
        table(rows, "all noise levels")
    goals(rows)
    misses(rows)
    if args.json:
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump(rows, fh, indent=1, default=str)
        print(f"\nper-case rows: {args.json}")


if __name__ == "__main__":
    main()
