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
   (station 12) to the sensor (station 13) on 400 frequencies (20-225 Hz);
4. model reduction of that channel (240 states): modal truncation with
   static correction at several cutoffs, and balanced truncation at several
   orders against SLICOT ``AB09AD`` (``control.balred``): Hankel singular
   values, H-infinity error, a-priori bound, relative error on 20-225 Hz;
5. modal analysis at speed: the dense eigen-solve of the first-order system
   (``Rotor.modes``) against the sparse shift-invert Arnoldi solve of the
   lowest modes (``mutext.rotor.sparse_modal.sparse_modes``, ARPACK through
   ``scipy.sparse.linalg.eigs``) on the thesis rotor and on uniform shafts of
   48 to 192 Timoshenko elements with two disks and two bearings, with the
   largest relative difference of the frequencies; and a Campbell diagram
   of the thesis rotor (31 speeds);
6. tuning to virtual sine sweeps (``mutext.rig.measure``, 411 points per
   channel): bearing stiffness and density from 1 % noisy data, the crack
   depth ratio, and the thesis hand tuning (density and disk weight), with
   the recovered values, standard uncertainties, iterations and seconds.

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

from mutext.examples.friswell import FREQUENCIES_0_RPM as FRISWELL_0
from mutext.examples.friswell import FREQUENCIES_4000_RPM as FRISWELL_4000
from mutext.examples.friswell import rotor as friswell_rotor


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
    ap.add_argument("--skip-reduction", action="store_true", help="leave out the model-reduction section")
    ap.add_argument("--skip-tuning", action="store_true", help="leave out the tuning section")
    ap.add_argument("--skip-modal", action="store_true", help="leave out the dense/sparse modal section")
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
    if not args.skip_reduction:
        print()
        bench_reduction(th)
    if not args.skip_modal:
        print()
        bench_modal(th, max(3, args.repeat // 4))
    if not args.skip_tuning:
        print()
        bench_tuning(th)
    return 0


def uniform_rotor(n_el):
    """A 1.5 m, 50 mm steel shaft in ``n_el`` Timoshenko elements, disks at 1/3 and 2/3, bearings at the ends
    (Friswell et al.'s example 5.9.1 meshed finer)."""
    from mutext.rotor import BearingElement, DiskElement, Param, Rotor, ShaftElement
    E, G, rho = 211e9, 81.2e9, 7810.0
    mat = dict(E=Param("E", E, "Pa"), G=Param("G", G, "Pa"), rho=Param("rho", rho, "kg/m^3"))
    els = [ShaftElement(i, 1.5 / n_el, 0.05, 0.0, **mat) for i in range(1, n_el + 1)]
    els += [DiskElement.from_geometry(n_el // 3 + 1, 0.07, 0.28, 0.05, rho),
            DiskElement.from_geometry(2 * n_el // 3 + 1, 0.07, 0.35, 0.05, rho)]
    els += [BearingElement(1, 1e6, 100.0), BearingElement(n_el + 1, 1e6, 100.0)]
    return Rotor(els, name=f"uniform shaft, {n_el} elements")


def bench_modal(th, repeat):
    """Section 5: dense against sparse shift-invert modal analysis at speed."""
    from mutext.rotor import campbell
    from mutext.rotor.sparse_modal import sparse_modes
    from mutext.rotor.units import rpm_to_rad_s
    n = 6
    speed = rpm_to_rad_s(3000.0)
    print(f"modal analysis at 3000 rpm, lowest {n} modes: dense first-order eigen-solve (Rotor.modes) "
          "vs sparse shift-invert (sparse_modes)")
    print(f"{'model':<34} {'DOFs':>5} {'dense [s]':>10} {'sparse [s]':>11} {'speed-up':>9} {'max rel. diff':>14}")
    for m in [th] + [uniform_rotor(k) for k in (48, 96, 192)]:
        m.matrices()                                          # the build and modal damping, not timed
        t_d = median_time(lambda: m.modes(speed=speed, n=n), repeat)
        t_s = median_time(lambda: sparse_modes(m, speed, n), repeat)
        a = m.modes(speed=speed, n=n).frequencies_hz
        b = sparse_modes(m, speed, n).frequencies_hz
        print(f"{m.name[:34]:<34} {m.ndof:>5} {t_d:>10.4f} {t_s:>11.4f} {t_d / t_s:>9.1f} "
              f"{np.max(np.abs(b / a - 1)):>14.1e}")
    speeds = rpm_to_rad_s(np.linspace(0.0, 3000.0, 31))
    for method in ("dense", "sparse"):
        t_c = median_time(lambda: campbell(th, speeds, 4, method=method), 1)
        print(f"Campbell diagram of the thesis rotor, 31 speeds, 4 modes ({method}): {t_c:.2f} s")


def bench_reduction(th):
    """Section 4: reduction of the thesis rotor channel i12 -> x13."""
    import control as ct

    from mutext.lti import balance_states
    from mutext.rotor.analysis import blas_single_thread
    from mutext.rotor.reduction import (balanced_truncation, hankel_singular_values, modal_truncation,
                                        reduction_error)
    band = (20.0, 225.0)
    with blas_single_thread():
        G = th.state_space(inputs=["i12"], outputs=["x13"])
        print(f"model reduction, thesis rotor i12 -> x13 ({G.nstates} states); errors in m/A, "
              f"relative error on {band[0]:g}-{band[1]:g} Hz")
        print(f"{'modal, cutoff [Hz]':<22} {'states':>6} {'||G-Gr||inf':>12} {'rel. band err':>14} "
              f"{'without static corr.':>21} {'time [s]':>9}")
        for fc in (250.0, 400.0, 1000.0, 3000.0):
            red = modal_truncation(th, fc, inputs=["i12"], outputs=["x13"], band_hz=band)
            raw = modal_truncation(th, fc, inputs=["i12"], outputs=["x13"], band_hz=band,
                                   static_correction=False, hinf=False)
            print(f"{fc:<22g} {red.order:>6} {red.hinf_error:>12.3e} {red.max_relative_error:>14.2e} "
                  f"{raw.max_relative_error:>21.2e} {red.seconds:>9.3f}")
        try:
            import slycot
        except ImportError:
            slycot = None
        Gs, _ = balance_states(G)
        hsv = hankel_singular_values(G)
        if slycot is not None:
            A, B, C = (np.asarray(X, float) for X in (Gs.A, Gs.B, Gs.C))
            ref = slycot.ab09ad("C", "B", "N", A.shape[0], 1, 1, A, B, C, nr=1, tol=0.0)[-1]
            for thr in (1e-2, 1e-4, 1e-6):
                k = ref > thr * ref[0]
                d = np.max(np.abs(hsv[k] - ref[k]) / ref[k])
                print(f"  Hankel singular values above {thr:g} sigma_1 ({int(k.sum())}): largest relative "
                      f"difference to SLICOT AB09AD {d:.1e}")
        print(f"{'balanced, order':<22} {'bound':>12} {'||G-Gr||inf':>12} {'slycot err':>12} "
              f"{'rel. band err':>14} {'time [s]':>9}")
        for r in (4, 8, 12, 20):
            red = balanced_truncation(G, r, band_hz=band)
            ref_err = float("nan")
            if slycot is not None:
                ref_err = reduction_error(G, ct.balred(Gs, r), band)["hinf"]
            print(f"{r:<22} {red.bound:>12.3e} {red.hinf_error:>12.3e} {ref_err:>12.3e} "
                  f"{red.max_relative_error:>14.2e} {red.seconds:>9.3f}")


def bench_tuning(th):
    """Section 5: fits to virtual sweeps of the thesis rotor."""
    import os

    from mutext.rig import measure, sweep_frequencies
    from mutext.rotor import data_path, load_model, loads_model
    from mutext.rotor import units as U
    from mutext.rotor.tuning import tune

    f = sweep_frequencies()

    def sweeps(model, values=None, noise=None, seed=0, outs=(13, 24)):
        H = model.frf(f, inputs=["i12"], outputs=[f"x{s}" for s in outs], values=values).H
        return [measure(lambda w, k=k: H[k, 0], 0, 0, f, noise=noise, rng=seed + k, input_station=12,
                        output_station=s, input_quantity="current") for k, s in enumerate(outs)]

    def show(title, res, true):
        print(title)
        print(f"  {'parameter':<24} {'true':>12} {'start':>12} {'fitted':>12} {'std':>10} {'err/std':>8}")
        for k in res.parameters:
            t = true[k]
            print(f"  {k:<24} {t:>12.6g} {res.start[k]:>12.6g} {res.values[k]:>12.6g} {res.std[k]:>10.2g} "
                  f"{(res.values[k] - t) / res.std[k] if res.std[k] > 0 else float('nan'):>8.2f}")
        print(f"  {res.n_points} points, residual {res.residual_rms_db:.3f} dB / {res.residual_rms_deg:.3f} deg, "
              f"{res.status}, {res.iterations} iterations, {res.seconds:.2f} s "
              f"({res.n_solves} complex LU factorisations)")

    k0, rho0 = th.parameter("bearing2.k").value, th.parameter("rho").value
    truth = {"bearing2.k": 1.3 * k0, "bearing29.k": 1.3 * k0, "rho": 0.97 * rho0}
    for noise in (0.01, 0.002):
        res = tune(th, sweeps(th, truth, noise, 11), [("bearing2.k", "bearing29.k"), "rho"])
        show(f"bearing stiffness x1.3 (both bearings, one parameter) and density x0.97, {noise:.1%} noise, "
             "channels i12 -> x13, x24", res, {"bearing2.k+bearing29.k": 1.3 * k0, "rho": 0.97 * rho0})
    res = tune(th, sweeps(th, truth, 0.01, 11), [("bearing2.k", "bearing29.k"), "rho"], max_points=100)
    show("the same, 1 % noise, at most about 100 points per channel (select_points)", res,
         {"bearing2.k+bearing29.k": 1.3 * k0, "rho": 0.97 * rho0})
    text = open(data_path("rotor.toml")).read() + "\n[[crack]]\nstation = 15\ndepth_ratio = 0.4\n"
    cracked = loads_model(text, source="cracked", base_dir=os.path.dirname(data_path("rotor.toml")))
    res = tune(cracked, sweeps(cracked, None, 0.01, 5), ["crack15.depth_ratio"],
               start={"crack15.depth_ratio": 0.2})
    show("crack depth ratio at station 15 (true 0.4, start 0.2), 1 % noise", res, {"crack15.depth_ratio": 0.4})
    tuned = load_model(data_path("rotor.toml"), station_table=data_path("rotor_cracked.txt"))
    res = tune(th, sweeps(tuned, outs=(13,)), ["rho", "disk16.m"])
    dens = U.to_si(1.0, "density", "inch-pound")
    show("thesis hand tuning: density and disk weight of the healthy table fitted to the sweep of the "
         "cracked table (noise-free)", res, {"rho": 0.29 * dens, "disk16.m": 5.21 * U.POUND_MASS})
    print(f"  in table units: density {res.values['rho'] / dens:.6f} lb/in^3 (table 0.29), disk "
          f"{res.values['disk16.m'] / U.POUND_MASS:.6f} lb (table 5.21)")


if __name__ == "__main__":
    raise SystemExit(main())
