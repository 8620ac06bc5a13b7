"""Command line of the autograder: ``mutext grade``."""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from .core import EXERCISES, GradingError, grade

USAGE_ERROR = 2


def _parser():
    p = argparse.ArgumentParser(
        prog="mutext grade",
        description="Grade a submission offline: per-question points and feedback.",
        epilog="Exit code 0 whenever grading completed (whatever the score), 2 on wrong usage.")
    p.add_argument("exercise", nargs="?", help="exercise name (see --list); a unique prefix such as ex01 works")
    p.add_argument("submission", nargs="?", help="the student's .py file")
    p.add_argument("--list", action="store_true", help="list the exercises and exit")
    p.add_argument("--json", action="store_true",
                   help="write the Gradescope results.json (to stdout, or to --output) instead of the report")
    p.add_argument("--output", metavar="FILE", help="write results.json to FILE (the report still goes to stdout "
                                                    "unless --json is given)")
    p.add_argument("--time-limit", type=float, default=60.0, metavar="SECONDS",
                   help="wall-clock limit for importing the submission and for each question (default 60)")
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
    try:
        report = grade(args.exercise, args.submission, time_limit=args.time_limit)
    except GradingError as exc:
        print(f"mutext grade: error: {exc}", file=sys.stderr)
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
    return 0
