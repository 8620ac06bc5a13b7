"""The offline autograder (``mutext grade``): scores, feedback, time limits, integrity, CLI.

The submissions in ``tests/grading_submissions`` (ex01) are graded on the inputs of one seed
(tests/grading_harness.py): those the confined child is there for (the reference, the cheating, endless
and crashing ones) confined, once each, two at a time in the background; the stub, the wrong answers and
the files the command line tests grade go through the same grader with their functions run in this
process (confined with ``-m slow``, compared with the in-process run; a syntax error and an exception in
a function are graded confined in tests/test_grading_batch.py and tests/test_grading_hostile.py too).
"""
import json
import re

import numpy as np
import pytest

from grading_harness import SUBS, Submissions, assert_same_scores_and_feedback, full, memoised_grade, q
from mutext import cli
from mutext_grader import GradingError, cli_grade, grade
from mutext_grader import cli as grade_cli
from mutext_grader import ex01_two_mass_hinf as ex01
from mutext.grading.sandbox import _Events
from mutext_grader.solutions import ex01_two_mass_hinf as sol

EXERCISE = "ex01_two_mass_hinf"
LOOP_LIMIT = 8.0   # seconds per question for the endless-loop submission
SEED = 20240611

# ex01 submissions have no exNN_ prefix; the other exercises' submissions do
graded = Submissions(EXERCISE, SEED, extra={p.stem: p for p in SUBS.glob("*.py") if not re.match(r"ex\d\d_", p.stem)},
                     confined=("infinite_loop", "reference", "cheat_at_import", "cheat_in_functions", "wrong_types"),
                     time_limits={"infinite_loop": LOOP_LIMIT})
SUBMISSIONS = graded.paths
#: graded in this process by default, confined with -m slow
HERE = ("destabilizing", "missing_noise", "one_exception", "stub", "syntax_error", "wrong_weight")
@pytest.fixture
def cli_in_process(monkeypatch):
    """``mutext grade FILE --seed SEED`` grading through the harness: the run of a test here on that file
    (its functions run in this process); everything else the command line does is its own."""
    monkeypatch.setattr(grade_cli, "grade", memoised_grade(here=True))


# ----------------------------------------------------------------------------
# scores and feedback
# ----------------------------------------------------------------------------

def test_reference_solution_scores_full_marks():
    rep = graded("reference")
    assert rep.max_score == 10
    assert rep.score == 10, rep.text()
    assert "within 2 % of the optimal level" in q(rep, "d").output


def test_stub_scores_zero_and_says_not_implemented():
    rep = graded.here("stub")
    assert rep.score == 0
    for x in rep.questions:
        assert "not implemented yet" in x.output
        # the same error for every input is reported once
        assert x.output.count("not implemented") == 1


def test_wrong_weight_loses_points_in_b_only():
    rep = graded.here("wrong_weight")
    b = q(rep, "b")
    # z1 row wrong (f1 -> z1, u -> z1) in every call: 4 of the 6 channels that carry a signal
    assert b.score == pytest.approx(3 * 4 / 6, abs=0.01), rep.text()
    assert "the z1 weight looks like x_max instead of 1/x_max" in b.output
    assert "channel f1 -> z1 (disturbance to weighted x1)" in b.output
    assert full(rep, "a", "c", "d")
    assert rep.score == pytest.approx(9.0, abs=0.01)


def test_missing_noise_channel_is_named():
    rep = graded.here("missing_noise")
    b = q(rep, "b")
    assert b.score == pytest.approx(3 * 5 / 6, abs=0.01), rep.text()
    # the same in each of the three calls: said once, without the expected value
    assert b.output.count("channel f2 -> y (sensor noise) is missing: your model gives 0") == 1
    assert "expected" not in b.output and "0.0001" not in b.output
    assert full(rep, "a", "c", "d")


def test_destabilizing_controller_scores_zero():
    rep = graded.here("destabilizing")
    d = q(rep, "d")
    assert d.score == 0
    assert "unstable" in d.output and "s = 17.86" in d.output
    assert full(rep, "a", "b", "c")


def test_syntax_error_scores_zero_with_line():
    rep = graded.here("syntax_error")
    assert rep.score == 0
    for x in rep.questions:
        assert "could not be imported: SyntaxError" in x.output
        assert "syntax_error.py, line 6" in x.output


def test_exception_in_one_function_others_still_scored():
    rep = graded.here("one_exception")
    c = q(rep, "c")
    assert c.score == 0
    assert "ZeroDivisionError" in c.output and "in _peak" in c.output
    assert full(rep, "a", "b", "d")
    assert rep.score == 8


def test_infinite_loop_hits_time_limit_and_rest_is_graded():
    rep = graded("infinite_loop")
    c = q(rep, "c")
    assert c.score == 0 and c.status == "timeout"
    assert f"time limit of {LOOP_LIMIT:g} s exceeded" in c.output
    assert "first-order low-pass" in c.output   # names the input it was stuck on
    # (d) runs after (c) in a fresh child process
    assert full(rep, "a", "b", "d")
    assert rep.seconds < LOOP_LIMIT + 40


def test_wrong_types_and_shapes_are_reported():
    rep = graded("wrong_types")
    assert rep.score == 0
    assert "mechanical_model() returned ndarray, expected a control.StateSpace" in q(rep, "a").output
    assert "expected 3 inputs [f1, f2, u] and 3 outputs [z1, z2, y], got 2 inputs and 3 outputs" in q(rep, "b").output
    assert "hinf_norm() returned str 'large', expected a float" in q(rep, "c").output
    # os._exit in controller(): the process died, reported, nothing else lost
    assert "grading process ended" in q(rep, "d").output and "exit code 3" in q(rep, "d").output


# ----------------------------------------------------------------------------
# integrity
# ----------------------------------------------------------------------------

def test_reading_the_reference_is_blocked_and_reported():
    rep = graded("cheat_in_functions")
    a, b, c = q(rep, "a"), q(rep, "b"), q(rep, "c")
    assert (a.score, b.score, c.score) == (0, 0, 0)
    assert "integrity violation" in a.output and "importing mutext.examples" in a.output
    # the attempt was caught by the submission and an honest plant returned: still 0
    assert "opening" in b.output and "solutions/ex01_two_mass_hinf.py" in b.output
    assert "importing mutext_grader" in c.output
    assert all(x.status == "violation" for x in (a, b, c))
    assert full(rep, "d")


@pytest.mark.slow
@pytest.mark.parametrize("name", HERE)
def test_confined_run_agrees_with_the_run_in_process(name):
    """What the default run checks on the functions run in this process holds for the confined run."""
    assert_same_scores_and_feedback(graded(name), graded.here(name))


def test_module_level_violation_zeroes_everything():
    rep = graded("cheat_at_import")
    assert rep.score == 0
    assert any("importing mutext_grader" in n for n in rep.notes)
    assert all("integrity violation when the file was imported (importing mutext_grader)" in x.output
               for x in rep.questions)


def test_results_channel_ignores_lines_without_the_nonce(tmp_path):
    f = tmp_path / "results.jsonl"
    f.write_text(json.dumps({"event": "result", "phase": "a", "calls": []}) + "\n"
                 + "not json\n"
                 + json.dumps({"event": "boot", "nonce": "abc"}) + "\n"
                 + '{"event": "start", "nonce": "abc"')   # incomplete line: not read yet
    ev = _Events(f, "abc")
    assert [e["event"] for e in ev.read()] == ["boot"]


# ----------------------------------------------------------------------------
# feedback of the checks (in-process, no child)
# ----------------------------------------------------------------------------

def _value(sys_):
    return {"A": np.asarray(sys_.A).tolist(), "B": np.asarray(sys_.B).tolist(), "C": np.asarray(sys_.C).tolist(),
            "D": np.asarray(sys_.D).tolist(), "dt": 0}


SEED = 20240611


def _question(qid, seed=SEED):
    return next(x for x in ex01.questions(np.random.default_rng(seed)) if x.id == qid)


def test_swapped_masses_hint():
    qa = _question("a")
    outs = [{"ok": True, "value": _value(sol.mechanical_model(c.args[1], c.args[0], *c.args[2:]))}
            for c in qa.calls]
    score, fb = qa.check(outs)
    assert score == 0
    assert any("hint: it matches the model with m1 and m2 swapped" in line for line in fb)


def test_reordered_outputs_hint():
    import control as ct
    qb = _question("b")
    outs = []
    for c in qb.calls:
        P = sol.generalized_plant(**c.kwargs)
        outs.append({"ok": True, "value": _value(ct.ss(P.A, P.B, np.asarray(P.C)[[2, 1, 0]],
                                                       np.asarray(P.D)[[2, 1, 0]]))})
    score, fb = qb.check(outs)
    assert score < 3
    assert any("outputs in the order [y, z2, z1] instead of [z1, z2, y]" in line for line in fb)


def test_grid_norm_gets_named_feedback():
    qc = _question("c")
    outs = []
    for (label, s) in ex01._norm_systems(ex01._draw(np.random.default_rng(SEED))):
        w = np.arange(0.05, 100.0, 0.5)   # a coarse grid: misses the resonance peak at 10 rad/s
        g = max(np.linalg.norm(np.asarray(s(1j * x)).reshape(s.noutputs, s.ninputs), 2) for x in w)
        outs.append({"ok": True, "value": float(g)})
    score, fb = qc.check(outs)
    assert score < 2
    assert any("lightly damped" in line and "too low" in line for line in fb)


def test_reference_solution_agrees_with_the_library():
    from mutext.examples import two_mass
    from mutext.lti import freqresp, hinf_norm
    w = np.array([0.0, 1.0, 30.0, 300.0])
    for p in (two_mass.TwoMass(), two_mass.TwoMass(**ex01.OTHER)):
        kw = {k: getattr(p, k) for k in ex01.DEFAULTS}
        np.testing.assert_allclose(freqresp(sol.generalized_plant(**kw), w), freqresp(two_mass.plant(p), w),
                                   rtol=1e-12, atol=1e-15)
    for _, s in ex01._norm_systems():
        assert sol.hinf_norm(s) == pytest.approx(hinf_norm(s).value, rel=1e-8)
    _, gamma = ex01.reference_problem()
    assert gamma == pytest.approx(1.0069, abs=2e-4)


# ----------------------------------------------------------------------------
# command line and results.json
# ----------------------------------------------------------------------------

def test_json_output_has_gradescope_schema(tmp_path, capsys, cli_in_process):
    out = tmp_path / "results.json"
    code = cli_grade([EXERCISE, str(SUBMISSIONS["one_exception"]), "--output", str(out), "--seed", str(SEED)])
    assert code == 0
    printed = capsys.readouterr().out
    assert "Total: 8.00 / 10" in printed
    data = json.loads(out.read_text())
    assert isinstance(data["score"], float) and data["score"] == 8.0
    assert len(data["tests"]) == 4
    for t in data["tests"]:
        assert set(t) >= {"name", "score", "max_score", "output"}
        assert isinstance(t["score"], float) and isinstance(t["max_score"], float)
        assert isinstance(t["name"], str) and isinstance(t["output"], str)
    assert sum(t["score"] for t in data["tests"]) == data["score"]
    assert "ZeroDivisionError" in data["tests"][2]["output"]
    assert data == json.loads(json.dumps(graded.here("one_exception").to_gradescope()))   # the run the tests share


def test_json_to_stdout(capsys, cli_in_process):
    code = cli_grade(["ex01", str(SUBMISSIONS["syntax_error"]), "--json", "--seed", str(SEED)])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    assert data["score"] == 0.0 and [t["max_score"] for t in data["tests"]] == [2.0, 3.0, 2.0, 3.0]


def test_cli_misuse_exit_codes(capsys, tmp_path):
    assert cli_grade(["ex99_nope", str(SUBMISSIONS["stub"])]) == 2
    err = capsys.readouterr().err
    assert "unknown exercise 'ex99_nope'" in err and "ex01_two_mass_hinf" in err
    assert cli_grade([EXERCISE, str(tmp_path / "missing.py")]) == 2
    assert "submission file not found" in capsys.readouterr().err
    assert cli_grade([EXERCISE]) == 2
    assert cli_grade(["--bogus-option"]) == 2
    with pytest.raises(GradingError, match="unknown exercise"):
        grade("nope", SUBMISSIONS["stub"])


def test_cli_list_through_main_dispatch(capsys):
    assert cli.main(["grade", "--list"]) == 0
    assert EXERCISE in capsys.readouterr().out


def test_fmt_shows_nan_and_inf_as_real_numbers():
    from mutext_grader.compare import fmt
    assert fmt(float("nan")) == "nan" and fmt(np.nan) == "nan"
    assert fmt(float("inf")) == "inf" and fmt(-np.inf) == "-inf"
    assert fmt(2.0) == "2" and fmt(1 + 2j) == "1+2j" and fmt(0.0) == "0"
