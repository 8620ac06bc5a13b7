"""``mutext demo three-mass --trial NAME``: model-based identification on the three-mass rig.

Thesis sec. 3.4: the engineering model of the ECP 210a rig has a wrong mass,
damper and/or spring on cart 3; a mu-controller placed there, tuned so that
the model's cart-1 response follows the (uncertain) true rig, is the missing
dynamics.  The demo runs the W_z search with D-K iteration, reads the
controller as an added mass, damper and spring, and compares it with the
known difference D_u.
"""
from __future__ import annotations

import os
import sys
import time

from ..examples import three_mass
from ..mbi import identify, impedance_response, relative_error


def add_arguments(p):
    p.add_argument("--trial", default="1a", choices=list(three_mass.TRIALS),
                   help="thesis trial (1a, 1b: spring; 2: mass; 3: damper; 4, 5: all three, 5 with 10 %% uncertainty)")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of a report")
    p.add_argument("--quiet", action="store_true", help="no progress output")
    p.add_argument("--plots", metavar="DIR", help="save the responses / K against D_u / error figure (PNG) in DIR")


def solve(trial: str = "1a", out=sys.stderr):
    """Run one trial; everything the demo, the book and the tests report, as a dict."""
    tr = three_mass.TRIALS[trial]
    t0 = time.perf_counter()
    res = identify(**three_mass.mbi_arguments(tr), Wz=tr.Wz, out=out)
    band = res.fit.omega
    return {
        "trial": tr.name,
        "result": res,
        "mu": res.mu_upper,
        "mu_lower": res.mu_lower,
        "Wz": res.Wz,
        "fit": {"dm": res.fit.dm, "dc": res.fit.dc, "dk": res.fit.dk},
        "fit_sigma": dict(zip(("dm", "dc", "dk"), res.fit.sigma)),
        "fit_residual": res.fit.residual,
        "band_rad_s": list(res.fit.band),
        "Du": dict(tr.Du),
        "K_rel_error": relative_error(res.K, tr.Du, band, weight=res.fit.weight),
        "K_rel_error_unweighted": relative_error(res.K, tr.Du, band),
        # how far D_u itself moves across the uncertainty box, on the same band and weights
        "Du_spread": max(relative_error(impedance_response(d, band), tr.Du, band, weight=res.fit.weight)
                         for d in three_mass.du_box(tr)),
        "Wz_floor": res.floor.value,
        "controller_order": res.K.nstates,
        "tries": [{"Wz": t.Wz, "mu": t.mu_upper} for t in res.tries],
        "thesis": {"Wz": tr.Wz, "mu": tr.mu},
        "notes": list(res.notes),
        "seconds": time.perf_counter() - t0,
    }


def figure(r, samples: int = 8):
    """The MBI figure of a :func:`solve` result, with true systems sampled at random
    vertices of the uncertainty box (thesis Figs. 3.13-3.15 analogues)."""
    from .. import plots
    tr = three_mass.TRIALS[r["trial"]]
    U = three_mass.true_model(tr)
    trues = [U.at(U.values(d)) for d in U.sample(samples, rng=0, vertices=True)]
    return plots.mbi_figure(r["result"], trues, Du=tr.Du, title=f"three-mass trial {tr.name}")


def run(args) -> int:
    out = None if (args.quiet or args.json) else sys.stderr
    if args.json and not args.quiet:
        out = sys.stderr
    tr = three_mass.TRIALS[args.trial]
    if not args.json:
        e, t = tr.engineering, tr.true
        print(f"three-mass trial {tr.name} (thesis sec. 3.4): engineering m3={e.m3} kg, c3={e.c3} N s/m, "
              f"k3={e.k3} N/m; true m3={t.m3}, c3={t.c3}, k3={t.k3} (+/-{tr.uncertainty:.0%})")
        print("D-K iteration and W_z search (progress on stderr) ...", flush=True)
    r = solve(args.trial, out=out)
    if args.plots:
        os.makedirs(args.plots, exist_ok=True)
        fig = figure(r)
        path = os.path.join(args.plots, f"three_mass_trial_{tr.name}.png")
        fig.savefig(path, dpi=120)
        print(f"plot saved: {path}", file=sys.stderr if args.json else sys.stdout)
    if args.json:
        from ..cli import print_json
        print_json({k: r[k] for k in ("trial", "mu", "mu_lower", "Wz", "fit", "fit_sigma", "fit_residual", "Du", "K_rel_error", "K_rel_error_unweighted",
                                      "Du_spread", "Wz_floor", "controller_order", "tries", "thesis", "band_rad_s", "seconds")})
        return 0
    res = r["result"]
    print(f"W_z = {r['Wz']:.4g} m   mu <= {r['mu']:.4f} (lower bound {r['mu_lower']:.4f});"
          f" thesis: W_z = {tr.Wz:g} m, mu <= {tr.mu}")
    print(f"floor: no controller can certify W_z below {r['Wz_floor']:.4g} m (spread of the true rigs"
          f" at {res.floor.omega:.3g} rad/s)")
    print("tries: " + ", ".join(f"W_z={t['Wz']:.4g} -> mu={t['mu']:.4f}" for t in r["tries"]))
    print(f"controller order {r['controller_order']}; identifiable band "
          f"{r['band_rad_s'][0]:.3g}-{r['band_rad_s'][1]:.3g} rad/s")
    print(f"reading of K: {res.fit.description}")
    d = tr.Du
    print(f"expected D_u: mass {d['dm']:+.4g} kg, damper {d['dc']:+.4g} N s/m, spring {d['dk']:+.4g} N/m")
    print(f"relative error of K against D_u on the band (RMS weighted by the sensitivity): "
          f"{r['K_rel_error']:.2%} (unweighted {r['K_rel_error_unweighted']:.2%}); D_u itself moves by up to "
          f"{r['Du_spread']:.2%} across the uncertainty box")
    for n in r["notes"]:
        print(f"note: {n}")
    print(f"time: {r['seconds']:.1f} s")
    return 0
