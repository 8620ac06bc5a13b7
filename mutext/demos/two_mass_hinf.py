"""``mutext demo two-mass-hinf``: the two-mass H-infinity problem of thesis sec. 2.3.1.

Solves the problem by our LMI synthesis, compares the level with slycot's
Riccati-based ``hinfsyn``, checks the controller (closed-loop stability,
norm recomputed two ways) and optionally saves the analogues of thesis
Figures 2.6-2.8.
"""
from __future__ import annotations

import os
import sys
import time


from ..examples import two_mass
from ..hinf import hinfsyn, slycot_hinfsyn


def add_arguments(p):
    """Declare the subcommand's options on ``p``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The subcommand's parser.
    """
    p.add_argument("--json", action="store_true", help="print one JSON object instead of a report")
    p.add_argument("--plots", metavar="DIR", help="save Figures 2.6-2.8 analogues (PNG) in DIR")
    p.add_argument("--exact-weights", action="store_true",
                   help="use 1/0.035 and 1/50 instead of the thesis's rounded 28.6 and 0.02")


def slycot_gamma(P, nmeas, ncon):
    """Reference level from python-control/slycot (Riccati method); nan unless its controller confirms it.

    Parameters
    ----------
    P : control.StateSpace
        The generalized plant.
    nmeas, ncon : int
        Numbers of measurements and controls.
    """
    ref = slycot_hinfsyn(P, nmeas, ncon, timeout=30.0)
    return ref.gamma if ref.status == "verified" else float("nan")


def solve(params=two_mass.THESIS):
    """Everything the demo, the book and the tests report, as a dict.

    Parameters
    ----------
    params : mutext.examples.two_mass.TwoMass, optional
        The problem's parameters (default: the thesis's, with its rounded weights).
    """
    t0 = time.perf_counter()
    P = two_mass.plant(params)
    res = hinfsyn(P, 1, 1)
    seconds = time.perf_counter() - t0
    return {
        "result": res,
        "plant": P,
        "gamma": res.gamma,
        "gamma_slycot": slycot_gamma(P, 1, 1),
        "gamma_thesis": two_mass.THESIS_GAMMA,
        "closed_loop_hinf": res.closed_loop_norm,
        "closed_loop_hinf_slycot": res.closed_loop_norm_slycot,
        "controller_order": res.controller_order,
        "controller_poles": [[float(p.real), float(p.imag)] for p in res.controller_poles],
        "controller_rhp_poles": [[float(p.real), float(p.imag)] for p in res.controller_rhp_poles],
        "closed_loop_stable": bool(res.stable),
        "max_closed_loop_real_part": float(res.max_closed_loop_real_part),
        "seconds": seconds,
    }


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
    if getattr(args, "plots", None) is not None:
        from .._files import output_directory
        output_directory(args.plots, "--plots")     # checked before the work, not after it
    params = two_mass.TwoMass() if args.exact_weights else two_mass.THESIS
    if not args.json:
        print("two-mass H-infinity problem (thesis sec. 2.3.1): "
              f"m1={params.m1} kg, m2={params.m2} kg, k1={params.k1} N/m, k2={params.k2} N/m")
        print(f"weights: x1 {params.weight_x:.4g} 1/m, u {params.weight_u:.4g} 1/N, "
              f"f_e {params.f_max} N, noise {params.eta_max} m")
        print("solving the LMIs (Clarabel) ...", flush=True)
    out = solve(params)
    res = out["result"]
    if args.json:
        from ..jsonio import print_json
        print_json({k: out[k] for k in ("gamma", "gamma_slycot", "closed_loop_hinf", "closed_loop_hinf_slycot",
                                        "closed_loop_stable", "max_closed_loop_real_part", "controller_poles",
                                        "controller_rhp_poles", "seconds", "controller_order", "gamma_thesis")})
    else:
        print(res.summary())
        print(f"slycot hinfsyn (Riccati) gamma   = {out['gamma_slycot']:.6f}  "
              f"(relative difference {abs(out['gamma'] - out['gamma_slycot']) / out['gamma_slycot']:.1e})")
        print(f"thesis (MATLAB) reported gamma   = {two_mass.THESIS_GAMMA}  (why it differs: the book, chapter "
              f"'H-infinity control', section '0.9671 or 1.0069?')")
        print("controller poles: " + ", ".join(f"{p:.4g}" for p in res.controller_poles))
        print(f"time: {out['seconds']:.2f} s")
    if args.plots:
        from .. import plots
        os.makedirs(args.plots, exist_ok=True)
        files = plots.two_mass_hinf_figures(res, out["plant"], args.plots, thesis_gamma=two_mass.THESIS_GAMMA)
        print("plots saved: " + ", ".join(files), file=sys.stderr if args.json else sys.stdout)
    return 0
