"""A real analyzer export end to end, as a user runs it: convert, the resonance table, and a diagnosis against
a model that is not the structure measured.

The file is a hammer test of a free-free steel beam written by ``tests/analyzer_export.py`` (numpy and
pyuff, no mutext) as analyzers write it: accelerance, the 0 Hz line, a Latin-1 units label, two
reference nodes.  The model handed to the diagnosis is an eleven-mass chain that has nothing to do with
the beam: no hypothesis can explain the data, and the diagnosis must say so, list the measured
resonances it has no partner for, and write no fix.
"""
from __future__ import annotations

import json

import pytest

pytest.importorskip("pyuff")

from analyzer_export import write_hammer_test  # noqa: E402

from mutext.cli import main  # noqa: E402

CHAIN = 11


def chain_model(path):
    """An eleven-mass grounded chain with sensors at masses 1, 6, 9 and forces at 1 and 6 (the file's nodes)."""
    out = ['name = "eleven-mass chain (not the beam)"', 'units = "SI"']
    for i in range(1, CHAIN + 1):
        out += ["[[mass]]", f'name = "m{i}"', "mass = 0.178"]
    for i in range(1, CHAIN):
        out += ["[[spring]]", f'name = "k{i}"', "stiffness = 4.0e5", f'between = ["m{i}", "m{i + 1}"]']
    out += ["[[spring]]", 'name = "k0"', "stiffness = 2.0e3", 'between = ["m1", "ground"]']
    for i in range(1, CHAIN + 1):
        out += ["[[damper]]", f'name = "c{i}"', "damping = 2.0", f'between = ["m{i}", "ground"]']
    out += ["[[force]]", 'name = "f1"', 'mass = "m1"', "[[force]]", 'name = "f6"', 'mass = "m6"']
    for s in (1, 6, 9):
        out += ["[[sensor]]", f'name = "x{s}"', f'mass = "m{s}"']
    path.write_text("\n".join(out) + "\n", encoding="utf-8")
    return path


@pytest.mark.slow
def test_hammer_test_against_the_wrong_model_is_not_explained(tmp_path, capsys):
    # about two minutes of CPU (every kind of the library screened at the eleven stations); covered in the
    # default run by tests/test_analyzer_files.py (this export read, converted, its resonance table),
    # tests/test_uff.py::test_command_line_diagnose_reads_every_frf_of_a_uff_file (diagnose on a UFF file
    # from the command line) and tests/test_diagnose_open.py::test_not_explained_result_writes_no_fix
    # (a wrong model: no fix written)
    truth = write_hammer_test(tmp_path / "hammer.uff", seed=1, noise=0.01, lines=400)
    model = chain_model(tmp_path / "chain.toml")
    # 1. convert (notes on stderr: the 0 Hz line, the Latin-1 label, accelerance -> receptance)
    assert main(["frf", "convert", str(tmp_path / "hammer.uff"), str(tmp_path / "hammer.csv")]) == 0
    err = capsys.readouterr().err
    assert "0 Hz" in err and "Latin-1" in err
    # 2. the model-free resonance table
    assert main(["frf", "resonances", str(tmp_path / "hammer.uff"), "--json"]) == 0
    table = json.loads(capsys.readouterr().out)
    assert table
    # 3. the diagnosis against the chain
    out = tmp_path / "out"
    rc = main(["diagnose", str(model), str(tmp_path / "hammer.uff"), "--out", str(out), "--json"])
    assert rc == 0
    d = json.loads(capsys.readouterr().out)
    assert d["status"] == "not explained", d["headline"]
    assert d["headline"].startswith("NOT EXPLAINED")
    assert not d["confirmed"]
    assert not (out / "model_extended.toml").exists()
    # the measured resonances the chain has no partner for are listed; each is a true beam resonance
    unmatched = [u["freq_hz"] for u in d["unmatched_resonances"]["measured"]]
    assert unmatched
    for f in unmatched:
        assert min(abs(f / t - 1) for t in truth["freq_hz"]) < 0.01, (f, truth["freq_hz"])
    # what was done to the file is said
    assert any("0 Hz" in n for n in d["notes"]) and any("omega^2" in n for n in d["notes"])
