"""``mutext diagnose MODEL.toml DATA.csv [...] [--validate VAL.csv ...] [--repeat REP.csv ...] [--out DIR] [--json]``,
or ``mutext diagnose --batch DIR [--jobs N]`` for every data set under DIR."""
from __future__ import annotations

import os
import sys


def add_arguments(p):
    """Add the positional arguments and options of ``mutext diagnose`` to a parser.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The sub-command's parser (changed in place).
    """
    p.add_argument("model", nargs="?", help="model file (TOML): a lumped chain or a rotor")
    p.add_argument("data", nargs="*", help="measured FRF files (freq_hz,re,im with a '# key: value' header, or "
                                           "Universal File data set 58 .uff/.unv, all its FRFs)")
    p.add_argument("--validate", nargs="+", default=[], metavar="FILE",
                   help="FRF files held out of the fit, on which the gain is measured (default: every 5th "
                        "frequency of the fitted files)")
    p.add_argument("--repeat", nargs="+", default=[], metavar="FILE",
                   help="the same channels measured again at another excitation level (force amplitude), on the "
                        "same frequencies: compared with the measured files without a model, a chi-square test "
                        "against the noise; a response that depends on the level (a nonlinear structure) is said "
                        "first and no linear model is then called explained.  Not fitted.  A file's "
                        "'# excitation: 2 N' header line is reported when present")
    p.add_argument("--out", metavar="DIR", help="write the extended model, report.html, figures and "
                                                "diagnosis.json into DIR")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the report")
    p.add_argument("--alpha", type=float, default=0.01, help="false-alarm rate of the 'none' verdict (default 0.01)")
    p.add_argument("--noise", type=float, default=None,
                   help="relative noise level of the data (default: estimated from the data)")
    p.add_argument("--mbi", action="store_true",
                   help="also read the top finding by model-based identification (lumped chains; D-K iteration, "
                        "5-60 s more)")
    p.add_argument("--batch", metavar="DIR", help="diagnose every data set under DIR (a folder with model.toml and "
                                                  "measured/, optionally validate/ and repeat/, as 'mutext rig hide' "
                                                  "writes); reports beside the data, "
                                                  "summary.csv and index.html in DIR")
    p.add_argument("--jobs", type=int, default=1, help="parallel workers for --batch (-1: all cores)")
    p.add_argument("--scheduler", metavar="ADDRESS", default=None,
                   help="for --batch: run the data sets on a Dask cluster: the address of a running scheduler "
                        "(tcp://host:8786), or 'local' for a cluster of --jobs worker processes on this machine "
                        "(needs pip install -e '.[cluster]')")
    p.add_argument("--quiet", action="store_true", help="no progress output")


def _check_usage(args) -> None:
    """Usage mistakes, said before anything heavy is imported (exit code 2)."""
    from ..errors import UsageError
    if args.batch:
        if args.model or args.data or args.validate or args.repeat or args.out:
            raise UsageError("--batch takes a directory only (each data set holds its model and files)")
        return
    if args.jobs != 1 or args.scheduler:
        raise UsageError("--jobs and --scheduler are for --batch DIR (one diagnosis runs in one process)")
    if not args.model or not args.data:
        raise UsageError("give a model file and at least one measured FRF file (or --batch DIR); "
                         "mutext diagnose --help for the options")


def _batch(args, prog) -> int:
    from ..batch import diagnose_batch
    if args.scheduler:
        from ..batch import dask_backend
        with dask_backend(args.scheduler, workers=args.jobs) as where:
            prog(f"Dask: {where}", 0.0)
            rows = diagnose_batch(args.batch, jobs=-1, mbi=args.mbi, progress=prog)
    else:
        rows = diagnose_batch(args.batch, jobs=args.jobs, mbi=args.mbi, progress=prog)
    if args.json:
        import json
        print(json.dumps(rows, default=str))
        return 1 if rows and all(r["status"] != "ok" for r in rows) else 0
    print(f"{'data set':<28} {'run':<7} {'diagnosis':<17} {'effects':<36} {'gain':>7} {'right':>6}")
    for r in rows:
        name = os.path.relpath(r["data_set"], args.batch)
        effects = r.get("effects", "") if r["status"] == "ok" else r.get("error", "")[:60]
        gain = f"{r['gain']:.3g}" if r.get("gain") is not None else ""
        print(f"{name:<28} {r['status']:<7} {r.get('diagnosis', ''):<17} {effects:<36} {gain:>7} "
              f"{str(r.get('found', '')):>6}")
    keyed = [r for r in rows if "found" in r]
    failed = [r for r in rows if r["status"] != "ok"]
    print(f"{len(rows) - len(failed)} of {len(rows)} diagnosed" + (f", {len(failed)} failed" if failed else "")
          + (f"; right in {sum(bool(r['found']) for r in keyed)} of {len(keyed)} with an answer key" if keyed else ""))
    print(f"summary: {os.path.join(args.batch, 'summary.csv')}, {os.path.join(args.batch, 'index.html')}")
    return 1 if rows and len(failed) == len(rows) else 0


def run(args) -> int:
    """Run ``mutext diagnose``: one model and its data sets, or ``--batch DIR``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (the options of :func:`add_arguments`).

    Returns
    -------
    int
        Exit code: 0 when the diagnosis ran (for ``--batch``, when at least one data set was
        diagnosed), 1 when every data set of a batch failed.

    Raises
    ------
    mutext.errors.UsageError
        Options that do not go together (exit code 2).
    """
    _check_usage(args)
    from ..diagnose import diagnose
    from ..errors import ModelError
    from ..progress import ProgressLine
    from ..report import diagnosis_json, mbi_lines, write_diagnosis
    from ..rig import read_frfs
    prog = ProgressLine(enabled=not args.quiet)
    if args.batch:
        return _batch(args, prog)
    # read_frfs: a Universal File may hold several FRFs (data sets 58), all used
    if args.out is not None:
        from .._files import output_directory
        output_directory(args.out)        # checked before the work, not after it
    data = read_frfs(args.data)
    validate = read_frfs(args.validate) if args.validate else None
    repeat = read_frfs(args.repeat) if args.repeat else None
    res = diagnose(args.model, data, validate=validate, repeat=repeat, alpha=args.alpha, noise=args.noise,
                   progress=prog, mbi=args.mbi)
    if args.out:
        prog("writing the report", 1.0)
        write_diagnosis(res, args.out)
    if args.json:
        print(diagnosis_json(res))
    else:
        print(res.report())
        for line in mbi_lines(res):
            print(line)
        if args.out:
            print(f"report: {args.out}/report.html")
    sys.stdout.flush()
    return 0
