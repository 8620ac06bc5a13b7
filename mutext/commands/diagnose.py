"""``mutext diagnose MODEL.toml DATA.csv [...] [--validate VAL.csv ...] [--out DIR] [--json]``."""
from __future__ import annotations

import sys


def add_arguments(p):
    p.add_argument("model", help="model file (TOML): a lumped chain or a rotor")
    p.add_argument("data", nargs="+", help="measured FRF files (freq_hz,re,im with a '# key: value' header, or "
                                           "Universal File data set 58 .uff/.unv, all its FRFs)")
    p.add_argument("--validate", nargs="+", default=[], metavar="FILE",
                   help="FRF files held out of the fit, on which the gain is measured (default: every 5th "
                        "frequency of the fitted files)")
    p.add_argument("--out", metavar="DIR", help="write the extended model, report.html, figures and "
                                                "diagnosis.json into DIR")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the report")
    p.add_argument("--alpha", type=float, default=0.01, help="false-alarm rate of the 'none' verdict (default 0.01)")
    p.add_argument("--noise", type=float, default=None,
                   help="relative noise level of the data (default: estimated from the data)")
    p.add_argument("--mbi", action="store_true",
                   help="also read the top finding by model-based identification (lumped chains; D-K iteration, "
                        "5-60 s more)")
    p.add_argument("--quiet", action="store_true", help="no progress output")


def run(args) -> int:
    from ..diagnose import diagnose
    from ..progress import ProgressLine
    from ..report import to_json, write_diagnosis
    from ..rig import read_frfs
    prog = ProgressLine(enabled=not args.quiet)
    # read_frfs: a Universal File may hold several FRFs (data sets 58), all used
    data = read_frfs(args.data)
    validate = read_frfs(args.validate) if args.validate else None
    res = diagnose(args.model, data, validate=validate, alpha=args.alpha, noise=args.noise,
                   progress=prog, mbi=args.mbi)
    if args.out:
        prog("writing the report", 1.0)
        write_diagnosis(res, args.out)
    if args.json:
        print(to_json(res))
    else:
        print(res.report())
        if args.out:
            print(f"report: {args.out}/report.html")
    sys.stdout.flush()
    return 0
