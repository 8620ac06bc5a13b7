"""Command-line interface: ``mutext diagnose``, ``mutext rig``, ``mutext frf``, ``mutext rotor``, ``mutext demo``,
``mutext check`` and ``mutext grade``."""
from __future__ import annotations

import argparse
import sys

from .errors import MutextError, UsageError

# name -> (module, one-line description); modules expose add_arguments(parser) and run(args) -> int
DEMOS = {
    "diagnose": ("mutext.demos.diagnose",
                 "a model, data with a hidden effect, and the diagnosis: what is wrong, why, the gain once fixed"),
    "two-mass-hinf": ("mutext.demos.two_mass_hinf",
                      "two-mass H-infinity control (thesis sec. 2.3.1): gamma by LMI vs slycot, checked controller"),
    "two-mass-mu": ("mutext.demos.two_mass_mu",
                    "two-mass mu-synthesis, +/-2 % on m1, m2, k1, k2 (thesis sec. 2.3.2): D-K iteration, checked controller"),
    "three-mass": ("mutext.demos.three_mass",
                   "model-based identification on the three-mass rig (thesis sec. 3.4): unmodeled dynamics as a mu-controller"),
    "rotor": ("mutext.demos.rotor",
              "rotor finite-element model: natural frequencies, exciter FRF, Campbell diagram (1x/2x/3x), "
              "unbalance response, healthy and breathing-crack orbits"),
    "crack": ("mutext.demos.crack",
              "cracked rotor at speed (thesis ch. 4): breathing-crack sweep, sidebands, identification at the crack"),
}


def _demo_module(name):
    import importlib
    return importlib.import_module(DEMOS[name][0])


def _available_demos():
    import importlib.util
    out = {}
    for name, (mod, desc) in DEMOS.items():
        try:
            if importlib.util.find_spec(mod) is not None:
                out[name] = desc
        except ModuleNotFoundError:
            pass
    return out


def _cmd_demo(argv) -> int:
    demos = _available_demos()
    # no automatic --help here: 'mutext demo NAME --help' is the demo's own help
    p = argparse.ArgumentParser(prog="mutext demo", description="Run a demonstration.", add_help=False)
    p.add_argument("name", nargs="?", help="demo to run (see --list)")
    p.add_argument("--list", action="store_true", help="list the demos and exit")
    args, rest = p.parse_known_args(argv)
    if args.name is None and any(a in ("-h", "--help") for a in rest):
        args.list = True
    if args.list or args.name is None:
        width = max(len(n) for n in demos)
        for n, d in demos.items():
            print(f"{n:<{width}}  {d}")
        if args.name is None and not args.list:
            print("\nusage: mutext demo NAME [options]   (mutext demo NAME --help for options)")
        return 0
    if args.name not in demos:
        print(f"mutext demo: unknown demo '{args.name}'. Available: {', '.join(demos)}", file=sys.stderr)
        return 2
    mod = _demo_module(args.name)
    sub = argparse.ArgumentParser(prog=f"mutext demo {args.name}", description=demos[args.name])
    mod.add_arguments(sub)
    return int(mod.run(sub.parse_args(rest)) or 0)


# name -> (module, one-line description); modules expose add_arguments(parser) and run(args) -> int
COMMANDS = {
    "diagnose": ("mutext.commands.diagnose",
                 "what a model gets wrong against measured FRFs, its cause, the extended model and the gain"),
    "rig": ("mutext.commands.rig", "virtual rig: 'rig hide' writes a data set with a hidden effect"),
    "frf": ("mutext.commands.frf", "FRF files: 'frf convert' between mutext's CSV and Universal File data set 58, "
                                   "'frf resonances' the model-free resonance table of measured FRFs"),
    "rotor": ("mutext.commands.rotor", "rotor model files: 'rotor campbell' the Campbell diagram and critical "
                                       "speeds, 'rotor whirl' directional FRFs, 'rotor runup' a transient run-up"),
}


def _cmd_module(name, argv) -> int:
    import importlib
    mod_name, desc = COMMANDS[name]
    mod = importlib.import_module(mod_name)
    p = argparse.ArgumentParser(prog=f"mutext {name}", description=desc)
    mod.add_arguments(p)
    return int(mod.run(p.parse_args(argv)) or 0)


def _check_parser():
    p = argparse.ArgumentParser(
        prog="mutext check",
        description="Check an exercise file locally: run it, confined as the grader runs it, on sample inputs "
                    "drawn afresh, and say per function whether it runs and returns the right kind and shape of "
                    "value. It never says whether the values are right: grading happens on the instructor's side.",
        epilog="Exit code 0 when every function runs and returns the right kind of value, 1 when some do not, "
               "2 on wrong usage (unknown exercise, missing file, not a .py file).")
    p.add_argument("exercise", nargs="?", help="exercise name (see --list); a unique prefix such as ex01 works")
    p.add_argument("file", nargs="?", help="your .py file")
    p.add_argument("--list", action="store_true", help="list the exercises and their functions, and exit")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--time-limit", type=float, default=60.0, metavar="SECONDS",
                   help="wall-clock limit for importing the file and for each function (default 60)")
    p.add_argument("--seed", type=int, default=None, metavar="N",
                   help="draw the sample inputs from seed N (to repeat a check; the report prints its seed)")
    return p


def _cmd_check(argv) -> int:
    import json
    import math
    from pathlib import Path
    from .grading.check import CheckError, check, exercise_list
    from .grading.spec import EXERCISES, find_exercise
    p = _check_parser()
    try:
        args = p.parse_args(list(argv))
    except SystemExit as exc:     # --help, or wrong usage (argparse printed why)
        return 0 if not exc.code else 2
    if args.list:
        rows = exercise_list()
        if args.json:
            print(json.dumps([{"name": n, "title": t, "description": d, "functions": f} for n, t, d, f in rows],
                             indent=2))
            return 0
        width = max(len(n) for n, *_ in rows)
        for name, _, desc, funcs in rows:
            print(f"{name:<{width}}  {desc}")
            print(f"{'':<{width}}  functions: {', '.join(funcs)}")
        return 0
    if not args.exercise or not args.file:
        p.print_usage(sys.stderr)
        print("mutext check: error: EXERCISE and FILE are required (or --list)", file=sys.stderr)
        return 2
    if find_exercise(args.exercise) is None:
        print(f"mutext check: error: unknown exercise '{args.exercise}'. Available: {', '.join(EXERCISES)}",
              file=sys.stderr)
        return 2
    if not math.isfinite(args.time_limit) or args.time_limit <= 0:
        print(f"mutext check: error: --time-limit must be a positive number of seconds, got {args.time_limit:g}",
              file=sys.stderr)
        return 2
    path = Path(args.file)
    if not path.exists():
        print(f"mutext check: error: file not found: {args.file}", file=sys.stderr)
        return 2
    if not path.is_file() or path.suffix != ".py":
        print(f"mutext check: error: expected a Python file (.py), got {args.file}", file=sys.stderr)
        return 2
    if args.seed is not None and args.seed < 0:
        print("mutext check: error: --seed takes a non-negative integer", file=sys.stderr)
        return 2
    try:
        report = check(args.exercise, path, time_limit=args.time_limit, seed=args.seed)
    except CheckError as exc:
        print(f"mutext check: error: {exc}", file=sys.stderr)
        return 2 if exc.usage else 1
    print(json.dumps(report.to_dict(), indent=2) if args.json else report.text())
    return 0 if report.ok else 1


def _cmd_grade(argv) -> int:
    from .grading import cli_grade
    return cli_grade(argv)


def __getattr__(name):
    # ``from mutext.cli import print_json`` keeps working without importing numpy for every command
    if name == "print_json":
        from .jsonio import print_json
        return print_json
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("mutext")
    except PackageNotFoundError:     # a source tree on PYTHONPATH, not installed
        return "(not installed: source tree)"


def main(argv=None) -> int:
    """Entry point of the ``mutext`` command: run a subcommand and return its exit status.

    Parameters
    ----------
    argv : list of str, optional
        The command line without the program name (default: ``sys.argv[1:]``).

    Returns
    -------
    int
        The exit status.
    """
    try:
        return _main(argv)
    except BrokenPipeError:
        # output piped into e.g. `head`, which closed early (the help, a report): not an error of ours;
        # stdout goes to /dev/null so the interpreter's final flush does not raise again
        import os
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


def _main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv[:1] in (["--version"], ["-V"]):
        print(f"mutext {_version()}")
        return 0
    if argv[:1] == ["help"]:
        # 'mutext help' is the overview, 'mutext help CMD' the command's own help
        argv = ["--help"] if len(argv) == 1 else [argv[1], "--help"]
    if not argv or argv[0] in ("-h", "--help"):
        print("usage: mutext {diagnose,rig,frf,rotor,demo,check,grade,help} ...   (mutext --version)\n\n"
              "  diagnose MODEL.toml DATA.csv [...] [--validate VAL.csv ...] [--repeat AT_OTHER_LEVEL.csv ...]\n"
              "           [--out DIR] [--json]      what the model gets wrong, why, and the gain once fixed\n"
              "  diagnose --batch DIR [--jobs N]    every data set under DIR, summary.csv and index.html\n"
              "  rig hide --seed N --out DIR        a data set with a hidden effect to diagnose\n"
              "  frf convert IN OUT                 FRF file CSV <-> Universal File 58 (.csv, .uff, .unv)\n"
              "  frf resonances FILE [...] [--json] resonances of measured FRFs: f_n, damping, channels\n"
              "  rotor campbell MODEL.toml [--speeds 0:3000:31] [--plot FILE] [--json]\n"
              "                                     Campbell diagram, log decrement, 1x/2x/3x critical speeds\n"
              "  rotor whirl MODEL.toml --input I --output O [--speed RPM]\n"
              "                                     forward and backward whirl peaks (directional FRFs)\n"
              "  rotor runup MODEL.toml --unbalance STATION:KG:M --speeds START:STOP --duration S --output STATION\n"
              "                                     transient run-up or coast-down through the critical speeds\n"
              "  demo NAME [options]                run a demonstration (mutext demo --list)\n"
              "  check EXERCISE FILE [--json]       does your exercise file run and return the right kinds of\n"
              "                                     values? (never whether they are right; mutext check --list)\n"
              "  grade EXERCISE SUBMISSION [--json] score a submission offline (the instructor's grader)\n"
              "  grade EXERCISE DIR [--jobs N]      every submission in DIR: results per file, summary.csv\n")
        return 0
    cmd, rest = argv[0], argv[1:]
    try:
        if cmd == "demo":
            return _cmd_demo(rest)
        if cmd == "check":
            return _cmd_check(rest)
        if cmd == "grade":
            return _cmd_grade(rest)
        if cmd in COMMANDS:
            return _cmd_module(cmd, rest)
    except UsageError as exc:
        print(f"mutext {cmd}: error: {exc}", file=sys.stderr)
        return 2
    except MutextError as exc:
        print(f"mutext {cmd}: error: {exc}", file=sys.stderr)
        return 1
    print(f"mutext: unknown command '{cmd}' (expected one of diagnose, rig, frf, rotor, demo, check, grade)", file=sys.stderr)
    return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
