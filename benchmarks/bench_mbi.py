"""Benchmark: model-based identification on the three-mass trials (thesis sec. 3.4).

For every trial the W_z search with D-K iteration runs as in
``mutext demo three-mass --trial NAME``.  Columns: the accepted W_z and its
certified mu upper bound (thesis values beside them), the number of D-K runs
of the W_z search, the controller order, the mass-damper-spring reading of K
against the known difference D_u (relative error of each nonzero coefficient),
the RMS relative error of K itself against D_u on the identifiable band
(weighted by the sensitivity of the measured error to K, and unweighted), the
largest such distance of D_u itself across the uncertainty box, the fit
residual and the seconds per trial.  ``floor`` is
:func:`mutext.mbi.wz_floor`: no controller certifies a smaller W_z (with the
bound shaped by the spread, the floor of that bound).  ``weight`` is the shape
of the error bound (``identify(weight=...)``): ``flat`` (the thesis's) or
``spread``; ``band`` the identifiable band and ``dk sd`` the standard
uncertainty of the spring reading relative to D_u's spring, i.e. how well the
data determine it.

Usage::

    python benchmarks/bench_mbi.py [--trials 1a 1b 2 3 4 5] [--weights flat spread]
"""
from __future__ import annotations

import argparse
import time


def main(argv=None):
    from mutext.demos.three_mass import solve
    from mutext.examples.three_mass import TRIALS
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", nargs="+", default=list(TRIALS), choices=list(TRIALS))
    ap.add_argument("--weights", nargs="+", default=["flat"], choices=["flat", "spread"])
    a = ap.parse_args(argv)
    hdr = (f"{'trial':<5} {'weight':>6} {'band':>11} {'dk sd':>6} {'Wz [m]':>10} {'floor':>9} {'thesis':>9} {'mu':>7} {'thesis':>7} {'mu_low':>7} {'runs':>4} "
           f"{'order':>5} {'dm':>9} {'dc':>9} {'dk':>9} {'coef err':>8} {'K err':>7} {'K unw':>8} {'Du box':>7} {'resid':>7} {'seconds':>7}")
    print(hdr)
    print("-" * len(hdr))
    t0 = time.perf_counter()
    for name in a.trials:
        for weight in a.weights:
            r = solve(name, out=None, weight=weight)
            fit, du = r["fit"], r["Du"]
            coef = max(abs(fit[k] - v) / abs(v) for k, v in du.items() if v)
            band = f"{r['band_rad_s'][0]:.2g}-{r['band_rad_s'][1]:.2g}"
            sd = r["fit_sigma"]["dk"] / abs(du["dk"]) if du["dk"] else float("nan")
            print(f"{name:<5} {weight:>6} {band:>11} {sd:6.1%} {r['Wz']:10.4g} {r['Wz_floor']:9.4g} {TRIALS[name].Wz:9.4g} {r['mu']:7.4f} {TRIALS[name].mu:7.4f} "
                  f"{r['mu_lower']:7.4f} {len(r['tries']):4d} {r['controller_order']:5d} {fit['dm']:9.4g} "
                  f"{fit['dc']:9.4g} {fit['dk']:9.4g} {coef:8.2%} {r['K_rel_error']:7.2%} {r['K_rel_error_unweighted']:8.2%} {r['Du_spread']:7.2%} {r['fit_residual']:7.2%} "
                  f"{r['seconds']:7.1f}", flush=True)
    print(f"\ntotal {time.perf_counter() - t0:.0f} s.  D_u: 1a +186 N/m, 1b -186 N/m, 2 +1 kg, 3 +5 N s/m, "
          "4 and 5 all three; 'coef err' = worst relative error of the nonzero coefficients;\n"
          "'floor' = smallest W_z any controller can certify (spread of the true rigs); 'Du box' = how far\n"
          "D_u itself moves across the uncertainty box (same band and weights as 'K err').")


if __name__ == "__main__":
    main()
