"""Command line of the autograder: ``mutext grade EXERCISE FILE`` for one submission,
``mutext grade EXERCISE DIR [--jobs N]`` for a directory of them (:mod:`.batch`)."""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from .core import EXERCISES, GradingError, clean_name, grade, read_secret

USAGE_ERROR = 2
NOT_ISOLATED = 3


def _parser():
    p = argparse.ArgumentParser(
        prog="mutext grade",
        description="Grade a submission offline: per-question points and feedback. Given a directory, grade "
                    "every .py file in it: a results file per submission and a class summary CSV.",
        epilog="Exit code 0 whenever grading completed (whatever the score), 2 on wrong usage, 3 with "
               "--require-isolation when the run was not isolated; for a directory, "
               "1 if some submission could not be graded (named in the summary; the others are graded).")
    p.add_argument("exercise", nargs="?", help="exercise name (see --list); a unique prefix such as ex01 works")
    p.add_argument("submission", nargs="?", help="the student's .py file, or a directory of submissions "
                                                 "(every *.py file directly in it)")
    p.add_argument("--list", action="store_true", help="list the exercises and exit")
    p.add_argument("--json", action="store_true",
                   help="write the Gradescope results.json (to stdout, or to --output) instead of the report")
    p.add_argument("--output", metavar="FILE", help="write results.json to FILE (the report still goes to stdout "
                                                    "unless --json is given)")
    p.add_argument("--time-limit", type=float, default=60.0, metavar="SECONDS",
                   help="wall-clock limit for importing the submission and for each question (default 60)")
    p.add_argument("--require-isolation", action="store_true",
                   help="course mode: score 0 (exit code 3) unless the submission ran confined (isolation uid "
                        "or landlock; see docs/grading.md)")
    p.add_argument("--secret-file", metavar="FILE",
                   help="course mode: the course secret (random bytes only the grader has); each file's inputs "
                        "are drawn from it and the file's content, so the same file always gets the same inputs "
                        "and nobody without the secret can know them. Without it, inputs are drawn afresh each run")
    p.add_argument("--seed", type=int, default=None, metavar="N",
                   help="draw the inputs from seed N (to repeat a run; the report prints the seed it used)")
    b = p.add_argument_group("a directory of submissions")
    b.add_argument("--jobs", type=int, default=None, metavar="N",
                   help="submissions graded at once (default 1; -1: all cores); each still in its own confined "
                        "process")
    b.add_argument("--out", metavar="DIR", help="where <submission>.json and summary.csv go (default DIR/results)")
    b.add_argument("--quiet", action="store_true", help="no progress on stderr")
    return p


def main(argv) -> int:
    """Run ``mutext grade`` with the arguments ``argv``; return the exit code."""
    p = _parser()
    try:
        args = p.parse_args(list(argv))
    except SystemExit as exc:   # argparse exits on --help and on bad usage; we return codes instead
        return int(exc.code or 0)
    if args.list:
        width = max(len(n) for n in EXERCISES)
        for name, (_, desc) in EXERCISES.items():
            print(f"{name:<{width}}  {desc}")
        return 0
    if not args.exercise or not args.submission:
        p.print_usage(sys.stderr)
        print("mutext grade: error: EXERCISE and SUBMISSION are required (or --list)", file=sys.stderr)
        return USAGE_ERROR
    if not math.isfinite(args.time_limit) or args.time_limit <= 0:
        print(f"mutext grade: error: --time-limit must be a positive number of seconds, got {args.time_limit:g}",
              file=sys.stderr)
        return USAGE_ERROR
    if args.seed is not None and (args.seed < 0 or args.secret_file):
        print("mutext grade: error: --seed takes a non-negative integer and does not go with --secret-file",
              file=sys.stderr)
        return USAGE_ERROR
    args.secret = None
    if args.secret_file:
        try:
            args.secret = read_secret(args.secret_file)
        except GradingError as exc:
            print(f"mutext grade: error: {clean_name(exc)}", file=sys.stderr)
            return USAGE_ERROR
    if Path(args.submission).is_dir():
        if args.seed is not None:
            print("mutext grade: error: --seed is for one file (each file of a directory gets its own inputs)",
                  file=sys.stderr)
            return USAGE_ERROR
        return _batch(args)
    if args.jobs is not None or args.out is not None:
        print("mutext grade: error: --jobs and --out are for a directory of submissions; for one file use "
              "--output FILE", file=sys.stderr)
        return USAGE_ERROR
    try:
        report = grade(args.exercise, args.submission, time_limit=args.time_limit,
                       require_isolation=args.require_isolation, secret=args.secret, seed=args.seed)
    except GradingError as exc:
        print(f"mutext grade: error: {clean_name(exc)}", file=sys.stderr)
        return USAGE_ERROR
    results = report.to_gradescope()
    if args.output:
        try:
            Path(args.output).write_text(json.dumps(results, indent=2) + "\n")
        except OSError as exc:
            print(f"mutext grade: error: cannot write {args.output}: {exc.strerror or exc}", file=sys.stderr)
            return USAGE_ERROR
    if args.json and not args.output:
        print(json.dumps(results, indent=2))
    elif not args.json:
        print(report.text())
    return NOT_ISOLATED if args.require_isolation and not report.isolated else 0


def _batch(args) -> int:
    """``mutext grade EXERCISE DIR``: every submission in DIR, a results file each and summary.csv."""
    from mutext.progress import ProgressLine
    from .batch import grade_batch
    if args.output:
        print("mutext grade: error: --output names one results.json; for a directory the results go to "
              "--out DIR (default DIR/results)", file=sys.stderr)
        return USAGE_ERROR
    jobs = 1 if args.jobs is None else args.jobs
    try:
        res = grade_batch(args.exercise, args.submission, jobs=jobs, time_limit=args.time_limit, out_dir=args.out,
                          progress=ProgressLine(enabled=not args.quiet), require_isolation=args.require_isolation,
                          secret=args.secret)
    except GradingError as exc:
        print(f"mutext grade: error: {clean_name(exc)}", file=sys.stderr)
        return USAGE_ERROR
    for note in res.notes:
        print(f"mutext grade: note: {clean_name(note)}", file=sys.stderr)
    if args.json:
        rows = [{k: v for k, v in r.items() if k != "isolation_details"} for r in res.rows]
        print(json.dumps(rows, indent=2))
        return 1 if res.failed else 0
    print(_table(res))
    return 1 if res.failed else 0


def _table(res) -> str:
    """The class at a glance: a row per submission (indented, names and notes cleaned of control
    characters, so a file name or an error message cannot pose as a line of the grader's own), then
    the count, the mean and where the results are."""
    import os
    names = {id(r): clean_name(r["submission"]) for r in res.rows}
    width = max(12, *(len(n) for n in names.values()))
    qids = [qid for qid, _ in res.questions]
    lines = [f"Exercise {res.exercise}: {len(res.rows)} submissions in {clean_name(res.directory)}",
             f"  {'submission':<{width}}  " + " ".join(f"{q:>5}" for q in qids) + "  total  notes",
             f"  {'(points)':<{width}}  " + " ".join(f"{p:>5g}" for _, p in res.questions)
             + f"  {sum(p for _, p in res.questions):>5g}"]
    for r in res.rows:
        if r["status"] == "graded":
            cells = " ".join(f"{r.get(q, 0):>5.2f}" for q in qids) + f"  {r['score']:>5.2f}"
            notes = "; ".join(t for t in (r.get("integrity"), r.get("problems")) if t)
        else:
            cells = " ".join(f"{'-':>5}" for _ in qids) + f"  {'-':>5}"
            notes = f"NOT GRADED: {r.get('error', '')}"
        lines.append(f"  {names[id(r)]:<{width}}  {cells}  {clean_name(notes)[:100]}")
    graded = [r for r in res.rows if r["status"] == "graded"]
    line = f"{len(graded)} of {len(res.rows)} graded"
    if res.failed:
        line += f", {len(res.failed)} could not be graded ({', '.join(names[id(r)] for r in res.failed)})"
    if graded:
        mean = sum(r["score"] for r in graded) / len(graded)
        line += f"; mean {mean:.2f} / {graded[0]['max_score']:g}"
    isol = sorted({r.get("isolation", "none") for r in graded})
    lines.append(line + (f"; isolation: {', '.join(isol)}" if isol else "")
                 + (f"; {res.jobs} at a time" if res.jobs != 1 else "; one at a time"))
    lines.append(f"results: {clean_name(os.path.join(str(res.out_dir), '<submission>.json'))}; "
                 f"summary: {clean_name(res.summary)}")
    return "\n".join(lines)


def entry() -> int:
    """Console script ``mutext-grade`` (the same as ``mutext grade``)."""
    raise SystemExit(main(sys.argv[1:]))
