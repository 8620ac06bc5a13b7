"""Benchmark: model-based identification by convex model matching against the D-K search.

For each three-mass trial of thesis sec. 3.4 (and the cracked rotor of ch. 4, ``--crack``) both
routes of :func:`mutext.mbi.identify` run on the same true and engineering systems:

* ``D-K``: the W_z search with D-K iteration as ``mutext demo three-mass`` runs it
  (:func:`mutext.demos.three_mass.solve`; the crack: ``identify`` with its defaults, as
  ``mutext demo crack``), each try judged by its D-G bound on the regularised plant;
* ``convex``: :func:`mutext.mbi.identify_convex`, the SOCP in the Youla parameter of K on
  samples of the uncertainty box, the controller reduced, then certified on the
  unregularised plant by a D-G sweep judged by branch and bound on the real parameters.

Columns: ``floor`` (:func:`mutext.mbi.wz_floor`, half the widest gap of the sampled true
systems) and ``cheb`` (the Chebyshev radius of the samples, :func:`mutext.mbi.chebyshev_radius`):
no controller certifies less; each route's certified W_z, its mu upper bound (the convex route's
D-G bound beside it), K's order and the wall seconds of the whole identification (one BLAS
thread).  ``ratio`` = convex W_z / D-K W_z.

Measured (2 cores shared with other work, ``OMP_NUM_THREADS=1``)::

    MEASURED_TABLE

Usage::

    python benchmarks/bench_mbi_convex.py [--trials 1a 1b 2 3 4 5] [--crack] [--no-dk]
"""
from __future__ import annotations

import argparse
import os
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def _crack_case():
    """The cracked rotor as ``mutext demo crack`` sets it up: the measured sweep (40 % Mayes crack,
    noise 0.001, seed 0), the healthy model truncated at 250 Hz, the keyword arguments."""
    from mutext.examples import cracked_rotor as ex
    from mutext.rig import measure_rotor, with_noise
    from mutext.rotor import modal_truncation
    healthy, cracked = ex.healthy_rotor(), ex.cracked_rotor(0.4, breathing="mayes")
    exact = measure_rotor(cracked, ex.EXCITATION, ex.MEASUREMENT)
    f = exact.freq_hz
    measured = with_noise(exact, 0.001, rng=0)
    ports = dict(inputs=[ex.EXCITATION, ex.CONTROL_INPUT], outputs=[ex.MEASUREMENT, ex.CONTROL_OUTPUT])
    E = modal_truncation(healthy, 250.0, static_correction=False, band_hz=(float(f[0]), float(f[-1])),
                         hinf=False, **ports).system
    kw = dict(excitation=ex.EXCITATION, measurement=ex.MEASUREMENT, control_input=ex.CONTROL_INPUT,
              control_output=ex.CONTROL_OUTPUT, Ww=ex.THESIS["Ww"])
    return measured, E, kw


def _row(name, floor, cheb, dk, cv):
    dk_wz = f"{dk['Wz']:10.4g}" if dk else f"{'-':>10}"
    dk_mu = f"{dk['mu']:7.4f}" if dk else f"{'-':>7}"
    dk_n = f"{dk['order']:5d}" if dk else f"{'-':>5}"
    dk_s = f"{dk['seconds']:7.1f}" if dk else f"{'-':>7}"
    ratio = f"{cv.Wz / dk['Wz']:6.3f}" if dk else f"{'-':>6}"
    return (f"{name:<6} {floor:10.4g} {cheb:10.4g} | {dk_wz} {dk_mu} {dk_n} {dk_s} | {cv.Wz:10.4g} "
            f"{cv.mu_upper:7.4f} {cv.tries[[t.Wz for t in cv.tries].index(cv.Wz)].mu_dg:7.4f} "
            f"{cv.K.nstates:5d} {cv.seconds:7.1f} | {ratio}")


def main(argv=None):
    from mutext.examples import three_mass as tm
    from mutext.mbi import identify, identify_convex
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", nargs="*", default=list(tm.TRIALS), choices=list(tm.TRIALS))
    ap.add_argument("--crack", action="store_true", help="also the cracked rotor (measured FRF, no uncertainty)")
    ap.add_argument("--no-dk", action="store_true", help="the convex route only")
    a = ap.parse_args(argv)
    hdr = (f"{'case':<6} {'floor':>10} {'cheb':>10} | {'D-K Wz':>10} {'mu':>7} {'order':>5} {'seconds':>7} | "
           f"{'convex Wz':>10} {'mu':>7} {'mu D-G':>7} {'order':>5} {'seconds':>7} | {'ratio':>6}")
    print(hdr)
    print("-" * len(hdr), flush=True)
    wins = []
    for name in a.trials:
        dk = None
        if not a.no_dk:
            from mutext.demos.three_mass import solve
            r = solve(name, out=None)
            dk = {"Wz": r["Wz"], "mu": r["mu"], "order": r["controller_order"], "seconds": r["seconds"]}
        cv = identify_convex(**tm.mbi_arguments(tm.TRIALS[name]))
        print(_row(name, cv.floor.value, cv.lower, dk, cv), flush=True)
        wins.append(dk is None or cv.Wz <= dk["Wz"])
    if a.crack:
        measured, E, kw = _crack_case()
        dk = None
        if not a.no_dk:
            t0 = time.perf_counter()
            r = identify(measured, E, **kw)
            dk = {"Wz": r.Wz, "mu": r.mu_upper, "order": r.K.nstates, "seconds": time.perf_counter() - t0}
        cv = identify_convex(measured, E, **kw)
        print(_row("crack", cv.floor.value, cv.lower, dk, cv), flush=True)
        wins.append(dk is None or cv.Wz <= dk["Wz"])
    print(f"\nconvex W_z at or below the D-K route's in {sum(wins)} of {len(wins)} cases "
          "(W_z in m for a unit excitation; the crack: m for W_w = 0.1 A)")
    return 0 if all(wins) else 1


if __name__ == "__main__":
    sys.exit(main())
