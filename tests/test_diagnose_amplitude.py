"""diagnose with sweeps repeated at another excitation level: a response that depends on the level is said first.

The data come from ``benchmarks/_open_world.py``, written apart from the package (its cubic spring: single-
harmonic balance at a given force amplitude; its noise; ``tests/test_open_world_generator.py`` checks it).
A cubic spring measured at two force levels must be flagged, with the resonance that moved, and never called
explained; a linear chain measured twice (only the noise differs) must not be, and its diagnosis stays as it
was.
"""
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import _open_world as ow  # noqa: E402

from mutext.diagnose import diagnose  # noqa: E402
from mutext.errors import ModelError  # noqa: E402
from mutext.rig import FRF  # noqa: E402

NOISE = 0.01
#: the chain's spring k1 (m1-m2) with a cubic term: at 1 N its stiffness rises by this fraction at the largest
#: linear elongation (the generator's measure r); at 0.2 N by 1/25 of it
R_CUBIC = 0.05


def _chain():
    path = ow.example_path("three_mass")
    M, C, K = ow.read_chain(path).matrices()
    return path, M, C, K


def _sweeps(H, f, outs, rng, level):
    """f1 -> x1, x3 as the generator's measured channels, noisy at 1 %, the force amplitude in the header."""
    return [FRF(f, ow.add_noise(h, NOISE, rng), input_station=1, output_station=o + 1,
                   metadata={"excitation": level}) for h, o in zip(H, outs)]


@pytest.fixture(scope="module")
def cubic():
    """The three-mass chain with a hardening cubic k1, swept at 0.2 N (measured) and at 1 N (repeat)."""
    path, M, C, K = _chain()
    f = ow.band_grid(M, K)
    outs = [0, 2]
    d = ow.solve_response(M, C, K, 0, [0, 1], f)
    k3 = R_CUBIC * 842.3 / (0.75 * float(np.max(np.abs(d[0] - d[1]))) ** 2)
    rng = np.random.default_rng(7)
    low = _sweeps(ow.cubic_response(M, C, K, (0, 1), k3, 0.2, 0, outs, f), f, outs, rng, "0.2 N")
    high = _sweeps(ow.cubic_response(M, C, K, (0, 1), k3, 1.0, 0, outs, f), f, outs, rng, "1 N")
    # the peak of f1 -> x3 near the third resonance at both levels, noise-free, on a fine grid: how far it moved
    fine = np.arange(4.6, 5.3, 0.0005)
    peaks = [fine[np.argmax(np.abs(ow.cubic_response(M, C, K, (0, 1), k3, F, 0, [2], fine)[0]))] for F in (0.2, 1.0)]
    return path, low, high, ow.natural_frequencies(M, K), peaks[1] / peaks[0] - 1


def test_a_cubic_spring_at_two_force_levels_is_flagged_and_never_explained(cubic, tmp_path):
    path, low, high, fn, moved = cubic
    # the stiffness changes only (the cubic term is in a spring): the screen stays short
    d = diagnose(path, low, repeat=high, refit=0, only=lambda h: h.kind == "stiffness", out_dir=tmp_path)
    amp = d.amplitude
    assert amp.significant and amp.chi2 > 5 * amp.threshold, amp.as_dict()
    assert d.status in ("partly explained", "not explained") and not d.confirmed
    head = d.headline()
    assert head.startswith(d.status.upper() + ": the response depends on the excitation level"), head
    assert d.report().splitlines()[0] == "verdict: " + head
    assert d.notes[0].startswith("the response depends on the excitation level")
    assert f"threshold {amp.threshold:.1f}" in head and f"chi2 {amp.chi2:.1f}" in head
    # the levels as the files state them; the measured set is the lower one
    assert amp.levels == ("0.2 N", "1 N") and amp.lower == "measured"
    # the resonance that moved is named, at one of the chain's, and it moved up (the spring hardens)
    res = amp.resonance
    assert res is not None and min(abs(res["measured_hz"] / fn - 1)) < 0.02, res
    assert abs(res["shift"] - moved) < 0.004 and f"{res['measured_hz']:.4g} Hz moved" in head, (res, moved)
    # whatever the linear fit at 0.2 N found is written as not confirmed
    assert not (tmp_path / "model_extended.toml").exists()
    js = d.as_dict()["amplitude_dependence"]
    assert js["significant"] and js["resonance"]["channel"] == res["channel"]


def _linear_case():
    case = ow.make_case("three_mass", "in_library", "mass", 2, NOISE)
    rng = np.random.default_rng(11)
    # the same channels again at 2 N: a linear chain answers the same; only the noise is new
    again = [replace(f, response=ow.add_noise(h, NOISE, rng), metadata={"excitation": "2 N"})
             for f, h in zip(case.measured, case.clean)]
    return case, again


def test_a_linear_chain_measured_at_two_levels_is_not_flagged_and_its_diagnosis_unchanged():
    case, again = _linear_case()
    only = lambda h: h.kind in ("mass", "stiffness")                       # noqa: E731
    d0 = diagnose(case.model_path, case.measured, validate=case.validate, refit=0, only=only)
    d1 = diagnose(case.model_path, case.measured, validate=case.validate, repeat=again, refit=0, only=only)
    amp = d1.amplitude
    assert not amp.significant and amp.chi2 < amp.threshold, amp.as_dict()
    assert amp.levels == (None, "2 N") and amp.lower is None and amp.resonance is None
    assert d1.status == d0.status == "explained"
    assert [(f.kind, f.station, f.value, f.std) for f in d1.effects] == \
           [(f.kind, f.station, f.value, f.std) for f in d0.effects]
    assert d1.headline() == d0.headline() and d1.gain == d0.gain
    (note,) = [n for n in d1.notes if n not in d0.notes]
    assert "agree with the measured ones within the noise" in note and "adds nothing else" in note
    assert d1.notes[:len(d0.notes)] == d0.notes


def test_a_repeat_of_no_measured_channel_names_its_file(tmp_path):
    from mutext.rig import write_frf
    case = ow.make_case("three_mass", "none", "none", 0, NOISE)
    # f3 -> x1 is not measured (nor validated here): no twin to compare with
    other = replace(case.validate[-1])
    assert other.input_station == 3
    write_frf(tmp_path / "other_level.csv", other)
    with pytest.raises(ModelError, match="other_level.csv.*matches no measured channel"):
        diagnose(case.model_path, case.measured, repeat=[tmp_path / "other_level.csv"])
    # the same data again is not a repeat; nor is a repeat on other frequencies
    with pytest.raises(ModelError, match="same data"):
        diagnose(case.model_path, case.measured, repeat=[replace(case.measured[0])])
    shifted = replace(case.measured[0], freq_hz=case.measured[0].freq_hz + 0.001)
    with pytest.raises(ModelError, match="shares no frequency"):
        diagnose(case.model_path, case.measured, repeat=[shifted])


def test_the_command_line_takes_a_repeat_and_names_a_bad_one(tmp_path, capsys):
    from mutext.cli import main
    from mutext.rig import write_frf
    case = ow.make_case("three_mass", "none", "none", 0, NOISE)
    data = [str(write_frf(tmp_path / f"m{k}.csv", f)) for k, f in enumerate(case.measured)]
    bad = str(write_frf(tmp_path / "f3x1_high.csv", case.validate[-1]))
    assert main(["diagnose", case.model_path, *data, "--repeat", bad, "--quiet"]) == 1
    err = capsys.readouterr().err
    assert "f3x1_high.csv" in err and "matches no measured channel" in err and "Traceback" not in err
    assert main(["diagnose", "--batch", str(tmp_path), "--repeat", bad]) == 2


def test_the_command_line_reports_the_repeat_and_its_levels(cubic, tmp_path, capsys):
    from mutext.cli import main
    from mutext.rig import write_frf
    path, low, high, _, _ = cubic
    data = [str(write_frf(tmp_path / f"low{k}.csv", f)) for k, f in enumerate(low)]
    rep = [str(write_frf(tmp_path / f"high{k}.csv", f)) for k, f in enumerate(high)]
    assert main(["diagnose", path, *data, "--repeat", *rep, "--quiet"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("verdict: ") and "the response depends on the excitation level (measured at 0.2 N, " \
                                            "repeated at 1 N)" in out.splitlines()[0]


@pytest.mark.slow
def test_false_alarms_of_the_repeat_test_stay_near_alpha():
    """The same linear channels swept twice, 300 noise draws: the test flags about alpha of them."""
    from mutext.diagnose._amplitude import level_test, pair_channels, pair_noise
    from mutext.diagnose._channels import _resolve
    from mutext.lti import blas_single_thread
    from mutext.rotor.model import load_model
    path, M, C, K = _chain()
    eng = load_model(path)
    f = ow.band_grid(M, K)
    H = ow.solve_response(M, C, K, 0, [0, 2], f)
    alpha, n, flagged = 0.05, 300, 0
    with blas_single_thread():
        for seed in range(n):
            rng = np.random.default_rng(100 + seed)
            a = _resolve(eng, _sweeps(H, f, [0, 2], rng, "1 N"), "data")[0]
            b = _resolve(eng, _sweeps(H, f, [0, 2], rng, "1 N"), "repeat")[0]
            pairs = pair_channels(a, b)
            flagged += level_test(pairs, pair_noise(pairs), alpha).significant
    # binomial(300, 0.05): 15 +/- 3.8
    assert 4 <= flagged <= 27, flagged


def test_fitted_at_the_higher_level_the_model_is_judged_on_the_lower_one(cubic):
    """The files say the repeat is the lower level: the linear model fitted at 1 N is held against the 0.2 N
    sweeps, which it does not fit (the linearisation at 1 N is not the one at 0.2 N)."""
    path, low, high, _, _ = cubic
    d = diagnose(path, high, repeat=low, refit=0, only=lambda h: h.kind == "stiffness")
    amp = d.amplitude
    assert amp.significant and amp.levels == ("1 N", "0.2 N") and amp.lower == "repeat"
    assert d.status == "not explained" and not d.confirmed, d.report()
    assert "does not fit the repeat's (lower-level) data at the noise" in d.notes[0]
    assert d.headline().startswith("NOT EXPLAINED: the response depends on the excitation level (measured at 1 N")


def test_the_excitation_level_is_read_from_a_csv_header_or_a_universal_file_id_line(tmp_path):
    from mutext.diagnose._amplitude import _lower, level_of
    from mutext.rig import read_frf, write_frf
    f = FRF(np.array([1.0, 2.0]), np.array([1e-3, 2e-3j]), input_station=1, output_station=1,
            metadata={"excitation": "0.5 N"})
    assert level_of(read_frf(write_frf(tmp_path / "a.csv", f))) == "0.5 N"
    assert level_of(replace(f, metadata={"uff_id2": "mutext excitation=2N"})) == "2N"
    assert level_of(replace(f, metadata={})) is None
    assert _lower("0.5 N", "2 N") == "measured" and _lower("2N", "0.5N") == "repeat"
    assert _lower("0.5 N", "0.1 A") is None and _lower(None, "1 N") is None and _lower("1 N", "1 N") is None


def test_a_batch_data_set_with_a_repeat_folder_is_tested_for_amplitude_dependence(cubic, tmp_path):
    """``repeat/`` beside ``measured/`` in a batch data set: the summary row carries the flag."""
    import json
    import shutil

    from mutext.batch import diagnose_batch
    from mutext.rig import write_frf
    path, low, high, _, _ = cubic
    rows = {}
    d = tmp_path / "cubic"
    for sub, sweeps in (("measured", low), ("repeat", high)):
        (d / sub).mkdir(parents=True)
        for k, f in enumerate(sweeps):
            write_frf(d / sub / f"{sub[0]}{k}.csv", f)
    shutil.copy(path, d / "model.toml")
    for r in diagnose_batch(tmp_path):
        rows[Path(r["data_set"]).name] = r
    assert rows["cubic"]["status"] == "ok", rows["cubic"]
    assert rows["cubic"]["diagnosis"] in ("partly explained", "not explained")
    js = json.loads((tmp_path / "cubic" / "diagnosis" / "diagnosis.json").read_text(encoding="utf-8"))
    assert js["amplitude_dependence"]["significant"], js["amplitude_dependence"]
    assert js["amplitude_dependence"]["levels"] == {"measured": "0.2 N", "repeat": "1 N"}
