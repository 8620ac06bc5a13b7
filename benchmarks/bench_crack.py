"""Benchmark: the cracked rotor at speed (harmonic balance, time integration, sidebands, chapter 4).

Tables printed:

1. **Sweep time.**  The thesis sweep (20-225 Hz, 0.5 Hz, 411 frequencies,
   i12 -> x13) of the rotor with a 40 % Mayes breathing crack at 10 Hz:
   building the time-periodic model, the Ritz reduction (with its measured
   error), the analyzer FRF by harmonic balance (N = 6) on the reduced model,
   the same on the full 120-DOF model, and the brute-force time integration
   of the analyzer (700 ms settling, 40 revolutions, all frequencies at once)
   on the same frequencies; the ratio; and the largest difference between the
   analyzer by harmonic balance and by time integration (which includes the
   transient left after 700 ms, a real feature of the thesis's settings).
2. **Convergence in N** on the reduced model.
3. **Sideband detection**: over seeds, how often the detector says "once per
   revolution" for the breathing crack, "twice per revolution" for an open
   crack, and anything but "none" for the healthy rotor and a 20 % bearing
   change (false alarms; nominal rate 1 %), at two noise levels.
4. **Chapter-4 identification** (``mutext demo crack``): time, mu, W_z and the
   identified point-spring loss against the exact requirement.

Usage::

    python benchmarks/bench_crack.py [--seeds 10] [--skip-time-domain] [--skip-demo]
"""
from __future__ import annotations

import argparse
import time

import numpy as np


def sweep_times(skip_td: bool):
    from mutext.examples.cracked_rotor import cracked_rotor
    from mutext.rig import sweep_frequencies
    from mutext.rotor.periodic import analyzer_frf, periodic_rotor, stepped_sine
    f = sweep_frequencies()
    r = cracked_rotor()
    rows = []
    t = time.perf_counter()
    pr = periodic_rotor(r, inputs=["i12"], outputs=["x13"])
    rows.append(("build the time-periodic model (120 DOF)", time.perf_counter() - t, ""))
    t = time.perf_counter()
    red = pr.reduce(1000.0)
    rows.append(("Ritz reduction (cutoff 1 kHz)", time.perf_counter() - t,
                 f"{red.n} coordinates, error {red.reduction_error:.2g}"))
    t = time.perf_counter()
    hb = analyzer_frf(red, f).H[0, 0]
    t_hb = time.perf_counter() - t
    rows.append(("analyzer FRF, harmonic balance N=6, reduced", t_hb, f"{f.size} frequencies"))
    t = time.perf_counter()
    full = analyzer_frf(pr, f).H[0, 0]
    rows.append(("analyzer FRF, harmonic balance N=6, full", time.perf_counter() - t,
                 f"max diff to reduced {np.max(np.abs(full - hb)) / np.max(np.abs(full)):.2g} of the peak"))
    if not skip_td:
        td = stepped_sine(red, f)
        rel = np.abs(td["H"] - hb) / np.abs(hb)
        k = int(np.argmax(rel))
        rows.append(("analyzer by time integration (700 ms, 40 rev)", td["seconds"],
                     f"{td['steps_per_rev']} steps/rev; ratio {td['seconds'] / t_hb:.0f}x; largest diff "
                     f"{rel[k]:.2g} at {f[k]:g} Hz, median {np.median(rel):.2g}"))
    print("\n1. thesis sweep (20-225 Hz, 0.5 Hz), 40 % Mayes crack at 10 Hz")
    print(f"   {'step':<48} {'seconds':>8}  note")
    for name, sec, note in rows:
        print(f"   {name:<48} {sec:>8.2f}  {note}")
    return red


def convergence(red):
    from mutext.rig import sweep_frequencies
    from mutext.rotor.periodic import harmonic_convergence
    rows = harmonic_convergence(red, sweep_frequencies(), harmonics=(0, 1, 2, 3, 4, 5, 6, 8, 10))
    print("\n2. convergence of H_0 in the number of harmonics (reduced model, full sweep)")
    print(f"   {'N':>3} {'max change vs N=10':>20} {'seconds':>8}")
    for r in rows:
        print(f"   {r['harmonics']:>3} {r['max_change']:>20.2e} {r['seconds']:>8.3f}")


def detection(seeds: int):
    from mutext.diagnose import sideband_evidence
    from mutext.examples.cracked_rotor import cracked_rotor, healthy_rotor
    from mutext.rig import measure_rotor, with_noise
    from mutext.rotor import data_path, loads_model
    text = open(data_path("rotor.toml")).read()
    cases = {"breathing (mayes)": (cracked_rotor(), "once per revolution"),
             "open crack": (cracked_rotor(breathing="open"), "twice per revolution"),
             "healthy": (healthy_rotor(), "none"),
             "bearing -20 %": (loads_model(text.replace("stiffness = 1.0e7", "stiffness = 0.8e7", 1),
                                           base_dir=data_path("")), "none")}
    modes = healthy_rotor().natural_frequencies(n=8)
    exact = {k: measure_rotor(m, "i12", "x13") for k, (m, _) in cases.items()}
    print(f"\n3. sideband verdicts over {seeds} seeds (fraction with the expected verdict)")
    print(f"   {'case':<20} {'expected':<22} {'noise 0.05 %':>13} {'noise 0.1 %':>12} {'noise 0.5 %':>12}")
    for k, (_, want) in cases.items():
        fr = []
        for noise in (5e-4, 1e-3, 5e-3):
            ok = 0
            for s in range(seeds):
                d = with_noise(exact[k], noise, rng=100 + s)
                ok += sideband_evidence(d, modes, 10.0).verdict == want
            fr.append(ok / seeds)
        print(f"   {k:<20} {want:<22} {fr[0]:>13.2f} {fr[1]:>12.2f} {fr[2]:>12.2f}")


def demo():
    from mutext.demos.crack import solve
    o = solve(out=None)
    print("\n4. mutext demo crack (chapter-4 identification)")
    print(f"   seconds {o['seconds']:.1f}; mu {o['mu']:.4f}; W_z {o['Wz']:.3g} m; K order {o['K_order']}")
    print(f"   point-spring loss: required {o['equivalent_stiffness_loss']:.0f} N/m, read from K "
          f"{o['identified_stiffness_loss']:.0f} N/m ({100 * o['identified_error']:.1f} %), averaged crack "
          f"{o['mean_stiffness_loss']:.0f} N/m")
    print(f"   fit error {o['fit_error_before']:.3f} -> {o['fit_error_after']:.4f}; "
          f"reduction error {o['reduction_error']:.2g}")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--seeds", type=int, default=10)
    p.add_argument("--skip-time-domain", action="store_true")
    p.add_argument("--skip-demo", action="store_true")
    a = p.parse_args()
    red = sweep_times(a.skip_time_domain)
    convergence(red)
    detection(a.seeds)
    if not a.skip_demo:
        demo()


if __name__ == "__main__":
    main()
