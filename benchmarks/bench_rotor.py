"""Benchmark: rotor finite elements (mutext.rotor).

Prints

1. Friswell, Penny, Garvey & Lees, *Dynamics of Rotating Machines* (2010),
   example 5.9.1 (6 Timoshenko elements, two disks, 1 MN/m bearings): our
   natural frequencies against the published ones at 0 and 4000 rpm, with
   the relative error and the whirl direction;
2. model building and evaluation times: the symbolic (CasADi) build of the
   Friswell rotor and of the 30-station thesis rotor, one numeric evaluation of
   ``M, C, K, G, B`` (compiled CasADi functions), and a full
   ``matrices()`` call on a new parameter vector (including the modal-damping
   eigenproblem for the thesis rotor, which has 1 % modal damping);
3. the frequency response of the thesis rotor from the exciter current
   (station 12) to the sensor (station 13) on 400 frequencies (20-225 Hz).

Times are medians of repeated runs (wall clock, this machine, BLAS limited to one
thread where ``threadpoolctl`` is installed).

Usage::

    python benchmarks/bench_rotor.py [--repeat 20]
"""
from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

FRISWELL_0 = [86.66, 86.66, 274.31, 274.31, 716.78, 716.78]
FRISWELL_4000 = [85.39, 87.80, 251.78, 294.71, 600.18, 827.08]


def friswell_rotor():
    from mutext.rotor import BearingElement, DiskElement, Param, Rotor, ShaftElement
    E, G, rho = 211e9, 81.2e9, 7810.0
    mat = dict(E=Param("E", E, "Pa"), G=Param("G", G, "Pa"), rho=Param("rho", rho, "kg/m^3"))
    els = [ShaftElement(i, 0.25, 0.05, 0.0, **mat) for i in range(1, 7)]
    els += [DiskElement.from_geometry(3, 0.07, 0.28, 0.05, rho), DiskElement.from_geometry(5, 0.07, 0.35, 0.05, rho)]
    els += [BearingElement(1, 1e6), BearingElement(7, 1e6)]
    return Rotor(els, name="Friswell 5.9.1")


def median_time(fn, repeat):
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=20, help="repetitions per timing (default 20)")
    args = ap.parse_args(argv)
    from mutext.rotor import data_path, load_model
    from mutext.rotor.analysis import blas_single_thread
    from mutext.rotor.units import rpm_to_rad_s

    r = friswell_rotor()
    print("Friswell et al. (2010) example 5.9.1, natural frequencies [rad/s]")
    print(f"{'rpm':>5} {'mode':>4} {'published':>10} {'mutext':>10} {'rel. error':>11}  whirl")
    worst = 0.0
    for rpm, ref in ((0, FRISWELL_0), (4000, FRISWELL_4000)):
        md = r.modes(speed=rpm_to_rad_s(rpm), n=6)
        for k, (a, b, w) in enumerate(zip(ref, md.omega, md.whirl_direction()), start=1):
            e = (b - a) / a
            worst = max(worst, abs(e))
            print(f"{rpm:>5} {k:>4} {a:>10.2f} {b:>10.3f} {e:>+11.1e}  {w if rpm else '(degenerate pair)'}")
    print(f"largest relative error: {worst:.1e} (published values have 4-5 significant digits)\n")

    print("model building and evaluation [s]")
    print(f"{'model':<28} {'DOFs':>5} {'params':>6} {'symbolic build':>15} {'eval M,C,K,G,B':>15} "
          f"{'matrices()':>11}")
    path = data_path("rotor.toml")
    for name, make in (("Friswell 5.9.1", friswell_rotor), ("thesis rotor (rotor.toml)", lambda: load_model(path))):
        builds = []
        for _ in range(max(3, args.repeat // 5)):
            m = make()
            builds.append(m.build_seconds)
        p0 = m.values()
        t_eval = median_time(lambda: m.evaluate(p0), args.repeat)
        bump = iter(np.linspace(1.0, 1.01, 10 * args.repeat))

        def fresh():
            # a new parameter vector each call, so the modal-damping eigenproblem is really solved
            with blas_single_thread():
                m.matrices(p0 * next(bump))
        t_mat = median_time(fresh, args.repeat)
        print(f"{name:<28} {m.ndof:>5} {len(m.parameters):>6} {statistics.median(builds):>15.3f} "
              f"{t_eval:>15.2e} {t_mat:>11.2e}")
    print()

    th = load_model(path)
    f = np.linspace(20.0, 225.0, 400)
    th.frf(f[:5], inputs=["i12"], outputs=["x13"])     # warm-up
    t_frf = median_time(lambda: th.frf(f, inputs=["i12"], outputs=["x13"]), max(3, args.repeat // 4))
    t_ss = median_time(lambda: th.state_space(inputs=["i12"], outputs=["x13"]), max(3, args.repeat // 4))
    md = th.modes(n=4)
    print("thesis rotor (healthy table, bearings 1e7 N/m at stations 2 and 29, 600 rpm)")
    print(f"  first natural frequencies [Hz]: " + ", ".join(
        f"{x:.2f} ({w})" for x, w in zip(md.frequencies_hz, md.whirl_direction())))
    print(f"  FRF i12 -> x13 on 400 frequencies: {t_frf:.3f} s   ({t_frf / 400 * 1e3:.2f} ms per frequency)")
    print(f"  state-space model (mck_to_ss, {2 * th.ndof} states): {t_ss:.3f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
