"""Breathing crack of the thesis rotor: stepped-sine sidebands against the +/-1 combination response.

The rotor of the thesis (``mutext/data/rotor.toml``) with the rig's crack (station 15, a/D = 0.4,
Mayes breathing law) is swept at 10 Hz running speed, 20-225 Hz in 0.5 Hz steps
(:func:`mutext.rig.measure_rotor`), over relative noise levels.  For each level and seed the
detector (:func:`mutext.diagnose.sideband_evidence`) is given (a) the excitation-frequency FRF
only (stepped-sine sidebands f_n -+ kF) and (b) the same FRF with the responses at f + F and
f - F (``combination=(-1, 1)``, the off-diagonal harmonic transfer functions, whose noise is the
main channel's in absolute terms).  "once" = a once-per-revolution stiffness (a breathing crack)
was found.  Controls: the healthy rotor and the gaping notch (2x only) with the combination
channels must not show a once-per-revolution response.

Run: ``.venv/bin/python benchmarks/bench_combination.py [--seeds 3] [--quick]``.
"""
import argparse
import time

import numpy as np

from mutext.diagnose import sideband_evidence
from mutext.rig import measure_rotor
from mutext.rotor import data_path, loads_model

TEXT = open(data_path("rotor.toml")).read()
SPEED_HZ = 10.0
LEVELS = (0.0005, 0.003, 0.01, 0.03, 0.10, 0.30)


def rotor(law=None):
    extra = "" if law is None else f"[[crack]]\nstation = 15\ndepth_ratio = 0.4\nbreathing = '{law}'\n"
    return loads_model(TEXT + extra, base_dir=data_path(""))


def detect(model, modes, noise, seed):
    """(stepped-sine verdict, combination verdict) for one noisy sweep."""
    chans = measure_rotor(model, "i12", "x13", noise=noise, rng=seed, combination=(-1, 1))
    a = sideband_evidence(chans[0], modes, SPEED_HZ)
    b = sideband_evidence(chans, modes, SPEED_HZ)
    return a.verdict, b.verdict, b


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="one seed, no controls")
    args = ap.parse_args(argv)
    seeds = range(1, 2 if args.quick else args.seeds + 1)
    t0 = time.perf_counter()
    modes = rotor().natural_frequencies(n=6)
    cracked = rotor("mayes")
    print(f"thesis rotor, Mayes breathing crack a/D = 0.4 at station 15, {SPEED_HZ:g} Hz, "
          f"{len(seeds)} seed(s) per level")
    print(f"{'noise':>7} | {'(a) stepped-sine sidebands':>28} | {'(b) +/-1 combination response':>30}"
          f" | {'min p (b)':>9}")
    for lv in LEVELS:
        va, vb, pb = [], [], []
        for s in seeds:
            a, b, ev = detect(cracked, modes, lv, s)
            va.append(a == "once per revolution")
            vb.append(b == "once per revolution")
            pb.append(min(c.p_value for c in ev.combination))
        print(f"{100 * lv:6.2f}% | {f'{sum(va)}/{len(va)} once per revolution':>28} | "
              f"{f'{sum(vb)}/{len(vb)} once per revolution':>30} | {min(pb):9.1e}")
    if not args.quick:
        print("controls (combination channels, 1 % noise): verdict from the combination channels")
        for name, law in (("healthy rotor", None), ("gaping notch", "gaping")):
            out = [detect(rotor(law), modes, 0.01, s)[1] for s in seeds]
            print(f"  {name:14s}: " + ", ".join(out))
    print(f"({time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
