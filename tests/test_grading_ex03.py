"""Autograder of exercise ex03_free_decay: scores, feedback, integrity (mutext.sysid blocked).

The submissions ``tests/grading_submissions/ex03_*.py``, the reference
solution and the stub are graded once, two at a time in the background; the
feedback of each diagnosis is also checked in-process on constructed answers.
"""
import math

import numpy as np
import pytest

from grading_harness import ROOT, GradedSubmissions, full, q
from mutext import cli
from mutext_grader import ex03_free_decay as ex03
from mutext_grader import grade
from mutext_grader.solutions import ex03_free_decay as sol

EXERCISE = "ex03_free_decay"
graded = GradedSubmissions(EXERCISE)
SUBMISSIONS = graded.paths


# ----------------------------------------------------------------------------
# graded submissions
# ----------------------------------------------------------------------------

def test_reference_solution_scores_full_marks():
    rep = graded("reference")
    assert rep.max_score == 10
    assert [x.max_score for x in rep.questions] == [1.5, 1.5, 1.5, 1.5, 2, 2]
    assert rep.score == 10, rep.text()


def test_stub_scores_zero_without_crashing():
    rep = graded("stub")
    assert rep.score == 0
    for x in rep.questions:
        assert x.status == "ok"
        assert x.output.count("not implemented yet") == 1


def test_printed_eq_3_3_is_named():
    rep = graded("ex03_thesis_eq33")
    assert full(rep, "a1", "a2", "b2", "c")
    b1 = q(rep, "b1")
    assert b1.score == 0 and b1.output.count("this is m_c + m_w") == 3
    assert "m_c = m_w omega_w^2 / (omega_c^2 - omega_w^2)" in b1.output
    d = q(rep, "d")
    assert d.score == 0
    assert "thesis's printed eq. 3.3" in d.output and "follows from a mass m_c + m_w" in d.output
    assert rep.score == 6.5


def test_hz_instead_of_rad_per_s_is_named():
    rep = graded("ex03_hz")
    a1 = q(rep, "a1")
    assert a1.score == 0 and a1.output.count("Hz instead of rad/s") == 3
    assert full(rep, "a2", "b1", "b2", "c")
    d = q(rep, "d")
    assert math.isclose(d.score, 0.67)               # the mass is a ratio of frequencies: right in Hz too
    assert "1/(2 pi)^2 times the expected one" in d.output and "1/(2 pi) times" in d.output
    assert rep.score < 10


def test_decrement_not_divided_by_cycles_is_named():
    rep = graded("ex03_decrement_not_per_cycle")
    a2 = q(rep, "a2")
    assert a2.score == 0
    for n in (5, 8, 4):
        assert f"zeta is {n} times too large" in a2.output
    assert full(rep, "a1", "b1", "b2", "c")
    d = q(rep, "d")
    assert math.isclose(d.score, 1.33) and "divided by the number of cycles N" in d.output
    assert rep.score < 10


def test_every_wrong_submission_scores_less():
    for name in SUBMISSIONS:
        if name.startswith("ex03_"):
            assert graded(name).score < 10, name


# ----------------------------------------------------------------------------
# diagnoses, in-process
# ----------------------------------------------------------------------------

def _payload(x, kind):
    if kind == "array":
        x = np.asarray(x, dtype=float)
        return {"ok": True, "value": {"shape": list(x.shape), "data": x.ravel().tolist()}}
    return {"ok": True, "value": float(x)}


@pytest.fixture(scope="module")
def questions():
    return {x.id: x for x in ex03.questions()}


def _check(questions, qid, answer):
    qu = questions[qid]
    return qu.check([_payload(answer(*c.args, **c.kwargs), qu.kind) for c in qu.calls])


def test_full_marks_in_process(questions):
    for qid, qu in questions.items():
        score, fb = _check(questions, qid, getattr(sol, qu.function))
        assert math.isclose(score, ex03.POINTS[qid]), fb
        assert fb[0].startswith("correct")


def test_references_are_the_simulated_parameters(questions):
    """(a) compares with the damped frequency and the true zeta of each record; the solution is close."""
    for c in questions["a1"].calls:
        wn, wd, z = ex03.exact_values(*c.params)
        assert abs(sol.natural_frequency(*c.args) / wd - 1) < 1e-4
        assert abs(sol.damping_ratio(*c.args) / z - 1) < 0.01
        assert abs(wn / wd - 1) < ex03.RTOL_FREQ      # the undamped frequency passes too


def test_solution_peaks_are_the_library_detector():
    """The solution writes out :func:`mutext.sysid.decay_peaks` (a submission may not import it):
    both find the same peaks on every record of the exercise, noisy ones included."""
    from mutext.sysid import decay_peaks
    records = [ex03.record(*r[1:4]) for r in ex03.A_RECORDS]
    for _, m_c, k, c, m_w, noise, seed in ex03.D_CARTS:
        records += [ex03.record(m_c, k, c, noise, seed), ex03.record(m_c + m_w, k, c, noise, seed + 100)]
    for t, y in records:
        for got, ref in zip(sol.peaks(t, y), decay_peaks(t, y)):
            np.testing.assert_allclose(got, ref, rtol=1e-12, atol=0)


@pytest.mark.parametrize("qid, answer, text", [
    ("a1", lambda t, y, N: 2 * math.pi / sol.natural_frequency(t, y, N), "this is the period"),
    ("a1", lambda t, y, N: sol.natural_frequency(t, y, N) / N, "spans N ="),
    ("a2", lambda t, y, N: sol.damping_ratio(t, y, N) * 2 * math.pi * N, "divide by 2 pi N"),
    ("a2", lambda t, y, N: sol.damping_ratio(t, y, N) * 2 * math.pi, "zeta = delta / (2 pi)"),
    ("a2", lambda t, y, N: sol.damping_ratio(t, y, N) / math.log(10), "not log10"),
    ("a2", lambda t, y, N: -sol.damping_ratio(t, y, N), "earlier peak over later peak"),
    ("b1", lambda wc, ww, mw: mw * ww / (wc - ww), "not squared"),
    ("b1", lambda wc, ww, mw: sol.cart_mass(ww, wc, mw), "a negative mass"),
    ("b2", lambda w, m: w * m, "not squared"),
    ("b2", lambda w, m: (2 * math.pi * w) ** 2 * m, "(2 pi)^2 times"),
    ("c", lambda z, m, w: z * m * w, "factor 2 is missing"),
    ("c", lambda z, m, w: 2 * z * m * w / (2 * math.pi), "Hz instead of rad/s"),
])
def test_diagnoses(questions, qid, answer, text):
    score, fb = _check(questions, qid, answer)
    assert score == 0
    assert any(text in line for line in fb), fb


def test_identify_cart_diagnoses(questions):
    def wrong_size(*a):
        return sol.identify_cart(*a)[:2]

    score, fb = _check(questions, "d", wrong_size)
    assert score == 0 and any("must return the three numbers (m_c, k, c)" in line for line in fb)

    def delta_per_cycle(*a):
        m, k, c = sol.identify_cart(*a)
        return [m, k, 2 * math.pi * c]

    score, fb = _check(questions, "d", delta_per_cycle)
    assert math.isclose(score, 4 / 3) and any("2 pi times the expected one" in line for line in fb)


def test_bad_payloads_are_reported(questions):
    qu = questions["b1"]
    score, fb = qu.check([{"ok": False, "error": "boom"}, _payload(float("nan"), "float"),
                          _payload(sol.cart_mass(*qu.calls[2].args), "float")])
    assert math.isclose(score, 0.5)
    assert any("boom" in line for line in fb) and any("got nan" in line for line in fb)


def test_listed_stub_and_blocked_modules():
    assert ex03.EXERCISE.stub == "exercises/ex03_free_decay.py"
    assert (ROOT / ex03.EXERCISE.stub).is_file()
    assert "mutext.sysid" in ex03.EXERCISE.blocked_modules


def test_importing_mutext_sysid_is_blocked(tmp_path):
    sub = tmp_path / "cheat.py"
    sub.write_text((ROOT / "exercises" / "ex03_free_decay.py").read_text() + "\n\n"
                   "def stiffness(omega_bare, m_c):\n"
                   "    import mutext.sysid\n"
                   "    return omega_bare**2 * m_c\n"
                   "\n\n"
                   "def cart_mass(omega_bare, omega_weighted, m_w):\n"
                   "    return m_w * omega_weighted**2 / (omega_bare**2 - omega_weighted**2)\n")
    rep = grade(EXERCISE, sub, 60.0)
    b2 = q(rep, "b2")
    assert b2.score == 0 and b2.status == "violation" and "importing mutext.sysid" in b2.output
    assert full(rep, "b1") and rep.score == 1.5


def test_cli_list_shows_ex03(capsys):
    assert cli.main(["grade", "--list"]) == 0
    out = capsys.readouterr().out
    assert EXERCISE in out and "ex04_beam_element" in out


def test_nan_answers_are_named_not_a_crash(questions):
    """NaN in (d) used to end in "could not be checked (ValueError: cannot convert float NaN ...)"."""
    nan = float("nan")
    score, fb = _check(questions, "d", lambda *a: [nan, nan, nan])
    assert score == 0
    assert not any("could not be checked" in line for line in fb)
    assert sum("the answer is NaN" in line for line in fb) == 6
    score, fb = _check(questions, "c", lambda *a: nan)
    assert score == 0 and all("got nan; the answer is NaN" in line for line in fb)
    assert not any("nan+0j" in line for line in fb)


def test_junk_values_get_no_factor_2_hint(questions):
    """A placeholder 1 is not "a factor 2" (ratios 0.51-0.52 of the references)."""
    for qid in questions:
        kind = questions[qid].kind
        score, fb = _check(questions, qid, lambda *a: [1.0, 1.0, 1.0] if kind == "array" else 1.0)
        assert not any("factor 2" in line for line in fb), (qid, fb)


def test_factor_2_hint_only_near_2():
    assert any("a factor 2" in h for h in ex03._ratio_hints(0.5, "c"))
    assert any("a factor 2" in h for h in ex03._ratio_hints(2.004, "c"))
    assert ex03._ratio_hints(0.5182, "c") == []
    assert ex03._ratio_hints(0.5122, "c", tol=1e-4) == []
    assert ex03._ratio_hints(float("nan"), "c") == []
