"""``mutext demo diagnose``: a model, data with a hidden effect, and the diagnosis.

The package's main job in one command: :func:`mutext.hide.hidden_effect_data`
hides an effect of random kind, place and size in a shipped model and
"measures" it with noise; :func:`mutext.diagnose.diagnose` is given only the
engineering model and the data, and must say what the model gets wrong, why,
and how much better the extended model is on held-out data.  The answer key
is revealed at the end.
"""
from __future__ import annotations

import os
import sys
import tempfile

from ..diagnose import diagnose
from ..hide import EXAMPLES, hidden_effect_data


def add_arguments(p):
    """Declare the subcommand's options on ``p``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The subcommand's parser.
    """
    p.add_argument("--example", default="four_story", choices=list(EXAMPLES),
                   help="shipped model hiding the effect (default four_story; rotor takes about a minute)")
    p.add_argument("--seed", type=int, default=5, help="seed of the hidden effect and the noise (default 5)")
    p.add_argument("--kind", default=None, help="force the kind of the hidden effect (default: random)")
    p.add_argument("--noise", type=float, default=0.01, help="relative measurement noise (default 0.01)")
    p.add_argument("--out", "--plots", dest="out", metavar="DIR",
                   help="write the data set (model, FRF files, answer key) and the report with figures in DIR")
    p.add_argument("--json", action="store_true", help="print one JSON object (diagnosis and answer key)")
    p.add_argument("--mbi", action="store_true", help="also read the finding by model-based identification "
                                                      "(lumped chains, D-K iteration: 5-60 s more)")
    p.add_argument("--quiet", action="store_true", help="no progress output")


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
    if getattr(args, "out", None) is not None:
        from .._files import output_directory
        output_directory(args.out, "--out")     # checked before the work, not after it
    from ..progress import ProgressLine
    from ..report import diagnosis_json, write_diagnosis
    out = args.out or tempfile.mkdtemp(prefix="mutext-diagnose-")
    case = hidden_effect_data(args.example, seed=args.seed, kind=args.kind, noise=args.noise,
                              out_dir=os.path.join(out, "case"))
    f = case.files
    if not args.json:
        print(f"engineering model: {f['model']}")
        print(f"measured FRFs ({len(f['measured'])}), validation FRFs ({len(f['validate'])}) in "
              f"{os.path.dirname(f['measured'][0])}/.. ; an effect is hidden in them (answer key kept apart)")
        print("diagnosing ...", flush=True)
    d = diagnose(f["model"], f["measured"], validate=f["validate"],
                 progress=ProgressLine(enabled=not args.quiet), mbi=args.mbi)
    paths = write_diagnosis(d, os.path.join(out, "report")) if args.out else {}
    key = case.key
    v = d.verdict
    right = (v.kind, v.station) == (key["kind"], key["station"])
    if args.json:
        import json
        obj = json.loads(diagnosis_json(d))
        obj["answer_key"] = key
        obj["found"] = right
        print(json.dumps(obj))
        return 0
    print()
    print(d.report())
    print()
    print(f"answer key: {key['description']}" + ("" if key["kind"] == "none" else
                                                    f", {key['value']:+.5g} {key['unit']}"))
    if right and key["kind"] != "none":
        err = v.value - key["value"]
        print(f"found: kind and place right; size {v.value:+.5g} {key['unit']}, off by {err:+.3g} "
              f"({abs(err) / max(v.std, 1e-300):.1f} standard uncertainties, "
              f"{100 * abs(err) / abs(key['value']):.2g} %)")
    elif right:
        print("found: nothing beyond the noise, rightly")
    elif d.status != "explained":
        print(f"not named: the diagnosis says {d.status} (the answer was {key['kind']} at {key['station']})")
    else:
        print(f"not found: the verdict is {v.kind} at {v.station}" +
              ("; the answer is among the hypotheses it cannot tell apart" if any(
                  (a.kind, a.station) == (key["kind"], key["station"]) for a in d.ambiguous_with) else ""))
    if paths:
        print(f"report: {paths['report']}")
    sys.stdout.flush()
    return 0
