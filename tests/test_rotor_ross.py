"""The Campbell diagram of Friswell et al.'s example 5.9.1 against ROSS 3.1 (ross-rotordynamics).

ROSS 3.1 needs Python >= 3.13, so it runs in its own environment in a
subprocess, found as in ``benchmarks/bench_ross.py`` (``$MUTEXT_ROSS_PYTHON``,
else ``.venv-ross/bin/python``); without it the test is skipped.  The ROSS
process takes some 10-20 CPU seconds (import and numba compilation), hence
``slow``.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import bench_ross  # noqa: E402

SPEEDS_RPM = [0.0, 2000.0, 4000.0]
N_MODES = 6

#: After ``bench_ross.ROSS_BUILD``: ROSS's Campbell diagram, the lateral modes only (its elements also have
#: axial and torsional DOFs), sorted by frequency at each speed, with ROSS's whirl directions.
CAMPBELL = bench_ross.ROSS_BUILD + r'''
rotor = build(spec["rotors"][0])
n = spec["modes"]
camp = rotor.run_campbell(np.asarray(spec["speeds"]), frequencies=n + 4)
out = {"ross": rs.__version__, "omega": [], "whirl": []}
for i, sp in enumerate(spec["speeds"]):
    shapes = camp.modal_results[camp.speed_range[i]].shapes
    lat = sorted((float(camp.wd[i, j]), str(shapes[j].whirl)) for j in range(camp.wd.shape[1])
                 if shapes[j].mode_type == "Lateral")[:n]
    out["omega"].append([w for w, _ in lat])
    out["whirl"].append([d for _, d in lat])
print(json.dumps(out))
'''


@pytest.mark.slow
def test_campbell_friswell_against_ross():
    python = bench_ross.ross_python()
    if python is None or not Path(python).exists():
        venv = Path(__file__).resolve().parents[1] / ".venv-ross"
        pytest.skip(f"ROSS 3.1 needs Python >= 3.13: make {venv} (see benchmarks/bench_ross.py) "
                    "or set MUTEXT_ROSS_PYTHON")
    from mutext.examples.friswell import rotor
    from mutext.rotor import campbell
    from mutext.rotor.units import rpm_to_rad_s

    speeds = rpm_to_rad_s(np.asarray(SPEEDS_RPM))
    spec = bench_ross.ross_spec([6], N_MODES, 1, [1.0])
    spec["speeds"] = speeds.tolist()
    ref = bench_ross.run_ross(CAMPBELL, spec, python, timeout=600)
    assert ref["ross"].startswith("3.1")

    cd = campbell(rotor(), speeds, N_MODES)
    ours = cd.frequencies_hz * 2 * np.pi
    theirs = np.asarray(ref["omega"])
    assert theirs.shape == ours.shape
    np.testing.assert_allclose(ours, theirs, rtol=1e-6, atol=0)
    assert cd.direction[0] == ["degenerate"] * N_MODES          # 0 rpm: pairs, no whirl to compare
    for i in range(1, len(SPEEDS_RPM)):
        assert cd.direction[i] == [d.lower() for d in ref["whirl"][i]], SPEEDS_RPM[i]
