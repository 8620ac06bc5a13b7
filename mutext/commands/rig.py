"""``mutext rig hide --seed N --out DIR [--example NAME] [--kind K] [--noise R]``: data with a hidden effect."""
from __future__ import annotations

import json


#: data sets one ``rig hide --count`` call may write (a class or a study; each is a few files)
MAX_COUNT = 10_000


def add_arguments(p):
    """Declare the subcommand's options on ``p``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The subcommand's parser.
    """
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
    h.add_argument("--count", type=int, default=1,
                   help="write COUNT data sets, seeds SEED..SEED+COUNT-1, in DIR/case_<seed> (a class or a study)")
    h.add_argument("--show-key", action="store_true", help="also print the answer key")


def run(args) -> int:
    """Run the subcommand with the parsed ``args``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.

    Returns
    -------
    int
        The exit status.
    """
    import os
    from ..errors import ModelError, UsageError
    from ..hide import hidden_effect_data
    from .._files import output_directory
    if args.count < 1 or args.count > MAX_COUNT:
        raise UsageError(f"--count must be between 1 and {MAX_COUNT} (data sets of one call), got {args.count}")
    output_directory(args.out)
    if args.count > 1:
        for seed in range(args.seed, args.seed + args.count):
            hidden_effect_data(args.example, seed=seed, kind=args.kind, noise=args.noise,
                               out_dir=os.path.join(args.out, f"case_{seed}"))
        print(f"{args.count} data sets in {args.out}/case_<seed> (answer keys inside: keep them apart)")
        print(f"try: mutext diagnose --batch {args.out} --jobs 2")
        return 0
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
