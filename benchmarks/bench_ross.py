"""Benchmark: mutext.rotor against ROSS 3.1 (ross-rotordynamics) on the same rotors.

Prints, for rotors of 6, 48 and 200 Timoshenko elements (Friswell et al. 2010,
example 5.9.1 as published, undamped; and the same 1.5 m, 50 mm steel shaft
meshed finer as in ``bench_rotor.py`` section 5: two disks at 1/3 and 2/3,
bearings of 1 MN/m and 100 N s/m at the ends), the CPU times of

* build: the model from its element data to numeric global matrices (mutext:
  elements, ``Rotor`` (the CasADi assembly) and one ``matrices()`` call; ROSS:
  elements and ``Rotor``, which assembles the matrices);
* modal at 0 and at 4000 rpm, the lowest ``--modes`` modes: mutext's default
  ``Rotor.modes(speed=..., n=...)`` (``method="auto"``: the dense eigen-decomposition,
  or from 150 DOFs up the sparse shift-invert solve) and the sparse shift-invert
  ``mutext.rotor.sparse_modal.sparse_modes`` always, against ROSS's
  ``rotor.run_modal(speed, num_modes=2 n)`` (which returns ``n`` modes);
* FRF at 4000 rpm on ``--nfreq`` frequencies (2-200 Hz), force in x at the first
  disk to displacement in x at the second: ``mutext.rotor.analysis.frf`` against
  ROSS's ``run_freq_response(speed_range=..., speed=...)`` (ROSS's only FRF call:
  it always computes every input/output pair; FRF timed runs: ``--repeat // --frf-divisor``),

with the ratio mutext/ROSS per column (below 1: mutext is faster), and the
agreement of the two: the largest relative difference of the lateral natural
frequencies (the lowest ``--modes`` at 0 and 4000 rpm; ROSS's elements carry
axial and torsional DOFs too, whose modes are left out) and of the FRF.  The
same physics is modelled on both sides (Cowper's shear coefficient, rotary
inertia and gyroscopics of the shaft, disks from their geometry), so the
differences are at rounding level.

Fairness: both sides run in this session, one after the other, on the same
machine; each time is the median of ``--repeat`` runs of process CPU time
(``time.process_time``) after one untimed warm-up run (ROSS compiles numba
code on its first modal analysis; ROSS's caches of ``run_modal`` and
``run_freq_response`` are cleared before each run), with BLAS and OpenMP limited to one
thread on both sides (``threadpoolctl`` here; ``OMP_NUM_THREADS=1``,
``OPENBLAS_NUM_THREADS=1``, ``MKL_NUM_THREADS=1`` and ``threadpoolctl`` in
the ROSS process).  Imports and the interpreter start are not timed.  A sparse
solve that ARPACK does not finish at shift 0 is repeated at other shifts within the
timed run (counted in the output).  The default run takes some 5 CPU minutes,
most of them ROSS's FRF on 200 elements.

Measured (default options, both sides in one session on 2 shared cores; ratios mutext/ROSS of the
median process CPU time, below 1: mutext is faster)::

    rotor         DOFs (mutext/ROSS)  build  modes() 0 rpm  sparse 0  modes() 4000  sparse 4000   FRF
    6 elements        28 / 42         0.31       0.13        0.23        0.34         0.44       0.25
    48 elements      196 / 294        0.59       0.14        0.15        0.20         0.17       0.11
    200 elements     804 / 1206       0.63       0.03        0.02        0.03         0.04       0.08

Natural frequencies agree to 9.1e-10 and the FRF to 2.0e-10 (relative).

ROSS 3.1 needs Python >= 3.13, so it runs in its own environment, in a
subprocess (the script ``ROSS_SCRIPT`` below, JSON in and out)::

    /root/.pyenv/versions/3.13.0/bin/python3.13 -m venv .venv-ross   # any Python >= 3.13
    .venv-ross/bin/pip install "ross-rotordynamics>=3.1,<3.2"
    .venv/bin/python benchmarks/bench_ross.py [--repeat 3] [--nfreq 10] [--frf-divisor 3] [--sizes 6 48 200]

The ROSS interpreter is ``$MUTEXT_ROSS_PYTHON``, else ``.venv-ross/bin/python``
of the repository if it exists; without one the ROSS columns say 'not run'
and the script says how to make it (exit status 0).
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
RPM = np.pi / 30.0
SPEEDS_RPM = (0.0, 4000.0)
HOW_TO = ("ROSS 3.1 needs Python >= 3.13: make its environment with\n"
          "    python3.13 -m venv .venv-ross && .venv-ross/bin/pip install \"ross-rotordynamics>=3.1,<3.2\"\n"
          "(in the repository root) or set MUTEXT_ROSS_PYTHON to a Python with ROSS 3.1.")

# Material and geometry of Friswell et al.'s example 5.9.1 [SI].
E, G_S, RHO = 211e9, 81.2e9, 7810.0
LENGTH, D_SHAFT, D_BORE = 1.5, 0.05, 0.05
DISKS = ((0.07, 0.28), (0.07, 0.35))          # (width, outer diameter) of the disks at 1/3 and 2/3
K_BEARING = 1e6


def ross_python() -> str | None:
    """The interpreter with ROSS: ``$MUTEXT_ROSS_PYTHON``, else ``.venv-ross/bin/python`` if it exists."""
    env = os.environ.get("MUTEXT_ROSS_PYTHON")
    if env:
        return env
    p = ROOT / ".venv-ross" / "bin" / "python"
    return str(p) if p.exists() else None


def ross_env() -> dict:
    """Environment of the ROSS process: one BLAS/OpenMP thread."""
    env = dict(os.environ)
    for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
        env[k] = "1"
    return env


def run_ross(script: str, spec: dict, python: str | None = None, timeout: float = 3600.0) -> dict:
    """Run ``script`` with the ROSS interpreter, ``spec`` as JSON on stdin; its last stdout line is JSON."""
    python = python or ross_python()
    if python is None:
        raise FileNotFoundError(HOW_TO)
    out = subprocess.run([python, "-c", script], input=json.dumps(spec), capture_output=True, text=True,
                         env=ross_env(), timeout=timeout, cwd=str(ROOT))
    if out.returncode != 0:
        raise RuntimeError(f"the ROSS process failed ({python}):\n{out.stderr[-3000:]}")
    lines = [ln for ln in out.stdout.splitlines() if ln.startswith("{")]
    if not lines:
        raise RuntimeError(f"the ROSS process printed no JSON ({python}):\n{out.stdout[-2000:]}")
    return json.loads(lines[-1])


def layout(n_el: int) -> dict:
    """Stations (1-based) of the disks and bearings and the bearing damping of the ``n_el``-element rotor:
    6 elements is Friswell 5.9.1 itself (undamped), finer meshes are ``bench_rotor.uniform_rotor``."""
    return {"n_el": n_el, "disks": [n_el // 3 + 1, 2 * n_el // 3 + 1], "bearings": [1, n_el + 1],
            "c": 0.0 if n_el == 6 else 100.0}


#: ROSS side, first part: reads the JSON spec from stdin, limits BLAS to one thread, ``build(layout)``.
ROSS_BUILD = r'''
import json, statistics, sys, time, warnings
warnings.filterwarnings("ignore")
spec = json.loads(sys.stdin.read())
try:
    from threadpoolctl import threadpool_limits
    threadpool_limits(1)
except ImportError:
    pass
import numpy as np
import ross as rs

def build(lay):
    steel = rs.Material(name="steel_friswell", rho=spec["rho"], E=spec["E"], G_s=spec["G_s"])
    n = lay["n_el"]
    shaft = [rs.ShaftElement(spec["length"] / n, 0.0, spec["d_shaft"], material=steel, shear_effects=True,
                             rotary_inertia=True, gyroscopic=True) for _ in range(n)]
    disks = [rs.DiskElement.from_geometry(n=s - 1, material=steel, width=w, i_d=spec["d_bore"], o_d=d)
             for s, (w, d) in zip(lay["disks"], spec["disks"])]
    brg = [rs.BearingElement(n=s - 1, kxx=spec["k"], kyy=spec["k"], cxx=lay["c"], cyy=lay["c"])
           for s in lay["bearings"]]
    return rs.Rotor(shaft, disks, brg)
'''

#: Runs in the ROSS interpreter after :data:`ROSS_BUILD`: times the rotors of the spec, prints one JSON line.
ROSS_SCRIPT = ROSS_BUILD + r'''
def timed(fn, repeat):
    fn()                                        # warm-up (numba compilation, caches)
    ts = []
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        ts.append(time.process_time() - t0)
    return statistics.median(ts)

def lateral(rotor, speed, n):
    """The lowest n lateral modes (ROSS also has axial and torsional ones): frequencies, whirl."""
    rotor.run_modal.cache_clear()
    m = rotor.run_modal(speed, num_modes=2 * (n + 6))
    keep = [i for i, s in enumerate(m.shapes) if s.mode_type == "Lateral"][:n]
    return [float(m.wd[i]) for i in keep], [str(m.shapes[i].whirl) for i in keep]

out = {"ross": rs.__version__, "rotors": []}
n, rep = spec["modes"], spec["repeat"]
for lay in spec["rotors"]:
    res = {"n_el": lay["n_el"]}
    rotor = build(lay)
    res["ndof"] = int(rotor.ndof)
    res["build"] = timed(lambda: build(lay), rep)
    res["modal"], res["omega"], res["whirl"] = [], [], []
    for sp in spec["speeds"]:
        def modal():
            rotor.run_modal.cache_clear()               # ROSS caches run_modal per rotor
            return rotor.run_modal(sp, num_modes=2 * n)
        res["modal"].append(timed(modal, rep))
        w, d = lateral(rotor, sp, n)
        res["omega"].append(w)
        res["whirl"].append(d)
    w = np.asarray(spec["freqs_rad"])
    i, o = 6 * (lay["disks"][0] - 1), 6 * (lay["disks"][1] - 1)

    def frf():
        rotor._run_freq_response.cache_clear()        # and run_freq_response
        return rotor.run_freq_response(speed_range=w, speed=spec["frf_speed"])
    res["frf"] = timed(frf, max(1, rep // spec.get("frf_divisor", 1)))
    H = frf().freq_resp[o, i, :]
    res["H"] = [[float(z.real), float(z.imag)] for z in H]
    out["rotors"].append(res)
    print(f"ROSS: {lay['n_el']} elements done", file=sys.stderr, flush=True)
print(json.dumps(out))
'''


def ross_spec(sizes, modes, repeat, freqs_hz, frf_divisor=1) -> dict:
    return {"E": E, "G_s": G_S, "rho": RHO, "length": LENGTH, "d_shaft": D_SHAFT, "d_bore": D_BORE,
            "disks": [list(d) for d in DISKS], "k": K_BEARING, "rotors": [layout(n) for n in sizes],
            "speeds": [s * RPM for s in SPEEDS_RPM], "modes": modes, "repeat": repeat,
            "freqs_rad": list(2 * np.pi * np.asarray(freqs_hz)), "frf_speed": SPEEDS_RPM[-1] * RPM,
            "frf_divisor": frf_divisor}


def mutext_rotor(n_el: int):
    """The ``n_el``-element rotor of :func:`layout` in mutext, with a force input and a displacement output
    in x at the disks (``f`` at the first, ``x`` at the second)."""
    from mutext.rotor import BearingElement, DiskElement, InputPort, OutputPort, Param, Rotor, ShaftElement
    lay = layout(n_el)
    mat = dict(E=Param("E", E, "Pa"), G=Param("G", G_S, "Pa"), rho=Param("rho", RHO, "kg/m^3"))
    els = [ShaftElement(i, LENGTH / n_el, D_SHAFT, 0.0, **mat) for i in range(1, n_el + 1)]
    els += [DiskElement.from_geometry(s, w, d, D_BORE, RHO) for s, (w, d) in zip(lay["disks"], DISKS)]
    els += [BearingElement(s, K_BEARING, lay["c"]) for s in lay["bearings"]]
    return Rotor(els, inputs=[InputPort("f", lay["disks"][0], "u")], outputs=[OutputPort("x", lay["disks"][1], "u")],
                 name=f"{n_el} elements")


def timed(fn, repeat):
    """Median process CPU time of ``repeat`` runs of ``fn`` after one untimed warm-up run."""
    fn()
    ts = []
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        ts.append(time.process_time() - t0)
    return statistics.median(ts)


#: Sparse solves that ARPACK did not finish and that were repeated at another shift.
RETRIES = []


def sparse(m, speed, n):
    """``sparse_modes(m, speed, n)``; on ARPACK's non-convergence (seen now and then on the undamped
    6-element rotor at 0 rpm) again with the shift at 0.5, 1, 0.25, 2 Hz and more vectors, each retry
    counted in :data:`RETRIES`."""
    from mutext.errors import ModelError
    from mutext.rotor.sparse_modal import sparse_modes
    for shift, extra in ((0.0, 8), (0.5, 12), (1.0, 16), (0.25, 20)):
        try:
            return sparse_modes(m, speed, n, shift_hz=shift, extra=extra)
        except ModelError:
            RETRIES.append((m.name, speed))
    return sparse_modes(m, speed, n, shift_hz=2.0)


def bench_mutext(sizes, modes, repeat, freqs_hz, frf_divisor=1) -> list[dict]:
    from mutext.rotor.analysis import frf
    out = []
    for n_el in sizes:
        def build():
            m = mutext_rotor(n_el)
            m.matrices()
            return m
        res = {"n_el": n_el, "build": timed(build, repeat)}
        m = build()
        res["ndof"] = m.ndof
        res["dense"], res["sparse"], res["omega"], res["omega_sparse"], res["whirl"] = [], [], [], [], []
        for rpm in SPEEDS_RPM:
            sp = rpm * RPM
            res["dense"].append(timed(lambda: m.modes(speed=sp, n=modes), repeat))
            res["sparse"].append(timed(lambda: sparse(m, sp, modes), repeat))
            md = m.modes(speed=sp, n=modes)
            res["omega"].append(md.omega.tolist())
            res["omega_sparse"].append(sparse(m, sp, modes).omega.tolist())
            res["whirl"].append(md.whirl_direction())
        sp = SPEEDS_RPM[-1] * RPM
        res["frf"] = timed(lambda: frf(m, freqs_hz, inputs=["f"], outputs=["x"], speed=sp),
                           max(1, repeat // frf_divisor))
        res["H"] = frf(m, freqs_hz, inputs=["f"], outputs=["x"], speed=sp).H[0, 0]
        out.append(res)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="timed runs per column (default 3)")
    ap.add_argument("--modes", type=int, default=6, help="modes per modal analysis (default 6)")
    ap.add_argument("--nfreq", type=int, default=10, help="FRF frequencies, 2-200 Hz (default 10)")
    ap.add_argument("--sizes", type=int, nargs="+", default=[6, 48, 200], help="numbers of elements")
    ap.add_argument("--frf-divisor", type=int, default=3,
                    help="FRF timed runs = repeat // this, at least 1 (default 3: ROSS's FRF is slow on fine meshes)")
    ap.add_argument("--ross-python", default=None, help="interpreter with ROSS 3.1 (default: see the docstring)")
    args = ap.parse_args(argv)
    from mutext.rotor.analysis import blas_single_thread

    freqs_hz = np.linspace(2.0, 200.0, args.nfreq)
    with blas_single_thread():
        ours = bench_mutext(args.sizes, args.modes, args.repeat, freqs_hz, args.frf_divisor)
    python = args.ross_python or ross_python()
    ross = None
    if python is None:
        print(HOW_TO + "\nThe ROSS columns are marked 'not run'.\n")
    else:
        print(f"running ROSS with {python} ...", flush=True)
        try:
            ross = run_ross(ROSS_SCRIPT, ross_spec(args.sizes, args.modes, args.repeat, freqs_hz, args.frf_divisor),
                            python)
        except (OSError, RuntimeError, subprocess.SubprocessError) as exc:
            print(f"ROSS not run: {exc}\n{HOW_TO}\n")

    ver = ross["ross"] if ross else "not run"
    print(f"\nmutext.rotor against ROSS {ver}: median process CPU time [s] of {args.repeat} runs, one BLAS thread; "
          f"{args.modes} modes; FRF on {args.nfreq} frequencies at {SPEEDS_RPM[-1]:g} rpm")
    cols = ["build", "modes() 0 rpm", "modal 0 sparse", "modes() 4000", "modal 4000 sp.", "FRF"]
    print(f"{'rotor':<13} {'':<14} {'DOFs':>5} " + " ".join(f"{c:>14}" for c in cols))
    worst_w, worst_h = 0.0, 0.0
    for k, a in enumerate(ours):
        mt = [a["build"], a["dense"][0], a["sparse"][0], a["dense"][1], a["sparse"][1], a["frf"]]
        name = f"{a['n_el']} elements"
        print(f"{name:<13} {'mutext':<14} {a['ndof']:>5} " + " ".join(f"{t:>14.4f}" for t in mt))
        if ross is None:
            print(f"{'':<13} {'ROSS':<14} {'':>5} " + " ".join(f"{'not run':>14}" for _ in cols))
            continue
        b = ross["rotors"][k]
        rt = [b["build"], b["modal"][0], b["modal"][0], b["modal"][1], b["modal"][1], b["frf"]]
        print(f"{'':<13} {'ROSS':<14} {b['ndof']:>5} " + " ".join(f"{t:>14.4f}" for t in rt))
        print(f"{'':<13} {'mutext/ROSS':<14} {'':>5} " + " ".join(f"{x / y:>14.2f}" for x, y in zip(mt, rt)))
        for i in range(len(SPEEDS_RPM)):
            ref = np.asarray(b["omega"][i])
            for mine in (a["omega"][i], a["omega_sparse"][i]):
                mine = np.asarray(mine)
                m = min(ref.size, mine.size)
                worst_w = max(worst_w, float(np.max(np.abs(mine[:m] / ref[:m] - 1))))
        Hr = np.array([complex(*z) for z in b["H"]])
        worst_h = max(worst_h, float(np.max(np.abs(a["H"] - Hr) / np.abs(Hr))))
    if RETRIES:
        print(f"ARPACK did not converge in {len(RETRIES)} sparse solves (repeated at another shift): "
              + ", ".join(sorted({f"{n} at {s / RPM:g} rpm" for n, s in RETRIES})))
    if ross is not None:
        print(f"\nagreement: largest relative difference of the lowest {args.modes} lateral natural frequencies "
              f"(0 and {SPEEDS_RPM[-1]:g} rpm, dense and sparse) {worst_w:.1e}; of the FRF {worst_h:.1e}")
        f0 = ours[0]
        print(f"{f0['n_el']} elements at {SPEEDS_RPM[-1]:g} rpm [rad/s]: mutext "
              + ", ".join(f"{w:.3f} ({d[0]})" for w, d in zip(f0["omega"][-1], f0["whirl"][-1])))
        print(f"{'':<27} ROSS   " + ", ".join(f"{w:.3f} ({d[0].lower()})" for w, d in
                                               zip(ross["rotors"][0]["omega"][-1], ross["rotors"][0]["whirl"][-1])))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
