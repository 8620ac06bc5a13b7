"""Rotor diagnosis against the number of stations: CPU time and peak memory at 30 and 59 stations.

The thesis rotor (``mutext/data/rotor.toml``, 30 stations) and the same rotor on a finer mesh: every shaft
element of its station table split into ``r`` equal elements (``r = 2``: 59 stations, 236 degrees of
freedom), the bearings, the exciter and the sensors at the same physical places, the ports keeping the names
of the shipped model (``x13`` is the sensor 0.05 in from the exciter whatever its station number), so that
:func:`mutext.hide.hidden_effect_data` hides an effect in either model and "measures" it the same way.

For each mesh and each hidden effect: the data set is written, then :func:`mutext.diagnose.diagnose` runs on
it (``refit=0``: the sizes as the screen fits them; the refit is a tune of the finite-element model, a
separate cost).  Printed: stations, DOFs, CPU seconds of the diagnosis (``time.process_time``, one BLAS
thread), peak traced memory (``tracemalloc``) in MB, the largest array the diagnosis holds, the verdict and
whether it is right (kind and station equal the answer key's), and the ratio of the 59-station figures to
the 30-station ones.

Usage::

    python benchmarks/bench_diagnose_scaling.py                  # 30 and 59 stations, a crack and a mass
    python benchmarks/bench_diagnose_scaling.py --refine 1 2 4   # also 117 stations
    python benchmarks/bench_diagnose_scaling.py --profile 2      # cProfile of the 59-station diagnosis

Measured (2 shared cores, one BLAS thread; CPU seconds and peak traced MB of ``diagnose(..., refit=0)``;
the data set is the same for both codes):

Before -- the receptance ``R = Z^-1`` held at every frequency and DOF, a dense solve per frequency for each
evaluation of the structure-wide hypotheses:

========  =====  ====  ======  =======  =========================  ========================  =====
stations  DOFs   hyps  CPU s   peak MB  largest array              verdict (size)            right
========  =====  ====  ======  =======  =========================  ========================  =====
30        120    130   57.1    351.6    R (821, 120, 120) 189 MB   crack at 21 (0.279)       yes
59        236    246   157.7   1321.6   R (821, 236, 236) 732 MB   crack at 42 (0.279)       yes
30        120    130   58.9    351.5    R (821, 120, 120) 189 MB   mass at 15 (0.2458)       yes
59        236    246   132.8   1321.5   R (821, 236, 236) 732 MB   mass at 29 (0.2458)       yes
========  =====  ====  ======  =======  =========================  ========================  =====

59 / 30 stations: crack CPU x2.76, memory x3.76; mass CPU x2.26, memory x3.76 (an earlier run on a busier
machine: crack 60.1 / 168.0 s, mass 63.4 / 173.4 s).

After -- the rotor's receptance from one eigen-decomposition of its state space
(:class:`mutext.diagnose._screen._Modal`), only the columns, rows and blocks used formed, a hypothesis's
pieces stacked over the channels; the damping scale one eigen-decomposition per value:

========  =====  ====  ======  =======  =========================  ========================  =====
stations  DOFs   hyps  CPU s   peak MB  largest array              verdict (size)            right
========  =====  ====  ======  =======  =========================  ========================  =====
30        120    130   27.3    12.7     modal.Y (240, 120) 0.5 MB  crack at 21 (0.279)       yes
59        236    246   52.9    29.5     modal.Y (472, 236) 1.8 MB  crack at 42 (0.279)       yes
30        120    130   27.6    12.5     modal.Y (240, 120) 0.5 MB  mass at 15 (0.2458)       yes
59        236    246   46.8    29.5     modal.Y (472, 236) 1.8 MB  mass at 29 (0.2458)       yes
117       468    478   115.3   95.6     modal.Y (936, 468) 7.0 MB  crack at 84 (0.279)       yes
========  =====  ====  ======  =======  =========================  ========================  =====

59 / 30 stations: crack CPU x1.94, memory x2.33; mass CPU x1.70, memory x2.35 (goal: within x2.5).
117 / 30 stations (crack, 30 stations at 25.5 s in that run): CPU x4.5, memory x7.5.  What still grows
faster than the stations: one eigen-decomposition of the 2n-state matrix per evaluation of the damping
scale (about 36 per diagnosis: 0.03 s at 120 DOFs, 0.15 s at 236, 1 s at 468; 40 s of the 117-station
run), the model's assembly and modes in :mod:`mutext.rotor` (peak 4 / 14 / 52 MB while the 30 / 59 /
117-station model file is read), and each receptance entry costing 2n products.  The sizes, stds and
gains of the rotor diagnoses agree with the dense inverse's to 1.4e-9 relative; lumped chains keep the
dense inverse (identical results).

With the refit of the best findings on the extended model file (``refit=3``, the package's default;
``--refit 3``).  Before, the refit was :func:`mutext.rotor.tuning.tune` on the finite-element model with a
dense solve per frequency: the crack at 30 stations 50.5 s (refit 22.8 s), 15.5 MB; 59 stations 136.2 s
(refit 70.4 s), 37.1 MB: x2.70 CPU, x2.39 memory -- the refit alone grew x3.1.  Now a rotor's refit
evaluates the extended model on its modes (``mutext.diagnose._extend._refit_on_modes``: the same
objective, one eigen-decomposition per value; sizes equal to tune's to 1.3e-4 of a std):

========  =====  ====  ======  =======  ==============================
stations  DOFs   hyps  CPU s   peak MB  verdict (size +/- std)
========  =====  ====  ======  =======  ==============================
30        120    130   35.4    14.2     crack at 21 (0.279 +/- 0.00012)
59        236    246   75.6    34.9     crack at 42 (0.279 +/- 0.00011)
========  =====  ====  ======  =======  ==============================

59 / 30 stations: CPU x2.13, memory x2.46 (goal: within x2.5).  Measured on a machine running other
work on both cores (the 30-station diagnosis with the tune refit took 53.7 s in the same session).
"""
from __future__ import annotations

import argparse
import os
import re
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

#: Ports of the shipped thesis rotor, named from its station table's flags (``ports_from_flags``).
_FLAG_COLUMNS = ("F", "x", "M", "psi")


def refined_rotor(out_dir, r: int) -> str:
    """The thesis rotor with every shaft element split into ``r`` equal elements, written to ``out_dir``.

    Returns the path of the model file.  ``r = 1`` is the shipped model's mesh (its ports declared
    explicitly instead of from the table's flags).  Station ``s`` of the shipped model is station
    ``(s - 1) r + 1`` of the refined one; the ports keep the shipped names.
    """
    from mutext.rotor import data_path
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rows, head = [], []
    for line in Path(data_path("rotor_healthy.txt")).read_text().splitlines():
        if not line.strip() or line.lstrip().startswith("#"):
            head.append(line)
            continue
        rows.append(line.split())
    new = lambda s: (s - 1) * r + 1
    table, ports = [], []
    for s, row in enumerate(rows, start=1):
        length = float(row[1])
        last = s == len(rows)
        table.append("\t".join([row[0], repr(length / r) if not last else row[1]] + row[2:8] + ["0"] * 4))
        for flag, name in zip(row[8:12], _FLAG_COLUMNS):
            if flag == "1":
                ports.append((name, s))
        if not last:
            for _ in range(r - 1):
                table.append("\t".join(["0", repr(length / r), row[2], row[3], "0", "0", row[6], row[7]]
                                       + ["0"] * 4))
    (out / "rotor_table.txt").write_text("\n".join(head + table) + "\n")
    text = Path(data_path("rotor.toml")).read_text()
    text = text.replace('station_table = "rotor_healthy.txt"', 'station_table = "rotor_table.txt"')
    text = text.replace("ports_from_flags = true", "ports_from_flags = false")
    text = re.sub(r"(?m)^(station\s*=\s*)(\d+)", lambda m: m.group(1) + str(new(int(m.group(2)))), text)
    text = text.replace('direction = "y"', 'direction = "y"\nname = "y13"')
    extra = []
    for name, s in ports:
        if name == "F":
            extra.append(f'[[force]]\nstation = {new(s)}\nname = "F{s}"\n')
        elif name == "x":
            extra.append(f'[[sensor]]\nstation = {new(s)}\nname = "x{s}"\n')
    path = out / "model.toml"
    path.write_text(text.rstrip("\n") + "\n\n" + "\n".join(extra))
    return str(path)


def run_case(r: int, kind: str, seed: int, work: Path, noise: float = 0.01, profile: bool = False,
             refit: int = 0) -> dict:
    """One hidden effect in the ``r``-times refined rotor, diagnosed: the figures of one table row."""
    import numpy as np

    from mutext.diagnose import diagnose
    from mutext.hide import hidden_effect_data
    from mutext.rotor import load_model
    case_dir = work / f"r{r}_{kind}_{seed}"
    model = refined_rotor(case_dir / "model", r)
    case = hidden_effect_data(model, seed=seed, kind=kind, noise=noise, out_dir=case_dir / "case")
    f = case.files
    eng = load_model(f["model"])
    n = eng.layout.n_nodes
    ndof = eng.matrices()[0].shape[0]
    # what the receptance holds: the arrays created while it is built
    from mutext.diagnose import _screen
    sizes = []
    orig = _screen._Receptance.__init__

    def spy(self, *a, **k):
        orig(self, *a, **k)
        held = dict(vars(self))
        modal = getattr(self, "modal", None)          # a rotor's receptance held as its modes
        if modal is not None:
            held.update({f"modal.{n}": v for n, v in vars(modal).items()})
        for name, v in held.items():
            if isinstance(v, np.ndarray):
                sizes.append((v.nbytes, name, v.shape))
    _screen._Receptance.__init__ = spy
    prof = None
    if profile:
        import cProfile
        prof = cProfile.Profile()
    try:
        tracemalloc.start()
        c0 = time.process_time()
        if prof:
            prof.enable()
        d = diagnose(f["model"], f["measured"], validate=f["validate"], refit=refit)
        if prof:
            prof.disable()
        cpu = time.process_time() - c0
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    finally:
        _screen._Receptance.__init__ = orig
    if prof:
        import pstats
        pstats.Stats(prof).sort_stats("cumulative").print_stats(30)
    big = max(sizes) if sizes else (0, "", ())
    key = case.key
    v = d.verdict
    return {"r": r, "stations": n, "dofs": ndof, "kind": kind, "seed": seed, "cpu": cpu, "peak_mb": peak / 1e6,
            "largest": f"{big[1]} {big[2]} {big[0] / 1e6:.1f} MB", "hypotheses": d.n_hypotheses,
            "verdict": f"{v.kind} at {v.station}", "value": float(v.value), "std": float(v.std), "key": f"{key['kind']} at {key['station']}",
            "key_value": float(key["value"]), "right": (v.kind, v.station) == (key["kind"], key["station"])}


HEAD = (f"{'stations':>8} {'dofs':>5} {'hyps':>5} {'CPU s':>8} {'peak MB':>8}  {'largest receptance array':<34} "
        f"{'verdict (size)':<26} {'answer (size)':<26} right")


def line(row) -> str:
    found = "{} ({:.4g} +/- {:.2g})".format(row["verdict"], row["value"], row["std"])
    answer = "{} ({:.4g})".format(row["key"], row["key_value"])
    return (f"{row['stations']:>8} {row['dofs']:>5} {row['hypotheses']:>5} {row['cpu']:>8.2f} {row['peak_mb']:>8.1f}  "
            f"{row['largest']:<34} {found:<26} {answer:<26} {'yes' if row['right'] else 'NO'}")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--refine", type=int, nargs="+", default=[1, 2], help="mesh refinements (1: 30 stations)")
    p.add_argument("--cases", nargs="+", default=["crack:4", "mass:1"],
                   help="hidden effects as kind:seed (default crack:4 mass:1)")
    p.add_argument("--profile", type=int, default=None, help="cProfile the diagnosis at this refinement")
    p.add_argument("--refit", type=int, default=0,
                   help="findings refitted on the extended model (default 0: the screen's sizes; the package's "
                        "default is 3)")
    args = p.parse_args(argv)
    from threadpoolctl import threadpool_limits
    rows = []
    print(HEAD, flush=True)
    with tempfile.TemporaryDirectory(prefix="bench-diag-scaling-") as tmp, threadpool_limits(1, "blas"):
        for spec in args.cases:
            kind, seed = spec.split(":")
            for r in args.refine:
                row = run_case(r, kind, int(seed), Path(tmp), profile=args.profile == r, refit=args.refit)
                rows.append(row)
                print(line(row), flush=True)
    base = {(x["kind"], x["seed"]): x for x in rows if x["r"] == min(args.refine)}
    print()
    for row in rows:
        b = base[(row["kind"], row["seed"])]
        if row is not b:
            print(f"{row['kind']}: {row['stations']} / {b['stations']} stations: CPU x{row['cpu'] / b['cpu']:.2f}, "
                  f"peak memory x{row['peak_mb'] / b['peak_mb']:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
