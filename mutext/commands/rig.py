"""``mutext rig hide --seed N --out DIR [--example NAME] [--kind K] [--noise R]``: data with a hidden effect."""
from __future__ import annotations

import json


def add_arguments(p):
    sub = p.add_subparsers(dest="action", required=True)
    h = sub.add_parser("hide", help="write a data set with a hidden effect (model, measured and validation "
                                    "FRFs, answer key apart)")
    from ..hide import EXAMPLES
    h.add_argument("--seed", type=int, required=True, help="random seed (kind, location, size, noise)")
    h.add_argument("--out", required=True, metavar="DIR", help="output directory")
    h.add_argument("--example", default="three_mass", help=f"shipped model ({', '.join(EXAMPLES)}) or a "
                                                             "lumped-chain model file (default three_mass)")
    h.add_argument("--kind", default=None, help="force the kind of effect (stiffness, mass, damping, bearing, "
                                                "crack, sensor_gain, exciter_gain, none)")
    h.add_argument("--noise", type=float, default=0.01, help="relative noise level (default 0.01 = 1 %%)")
    h.add_argument("--show-key", action="store_true", help="also print the answer key")


def run(args) -> int:
    from ..hide import hidden_effect_data
    case = hidden_effect_data(args.example, seed=args.seed, kind=args.kind, noise=args.noise, out_dir=args.out)
    f = case.files
    print(f"model:     {f['model']}")
    print(f"measured:  {' '.join(f['measured'])}")
    print(f"validate:  {' '.join(f['validate'])}")
    print(f"answer key (keep it apart): {f['answer_key']}")
    print(f"try: mutext diagnose {f['model']} {' '.join(f['measured'])} --validate {' '.join(f['validate'])}")
    if args.show_key:
        print(json.dumps(case.key, indent=2))
    return 0
