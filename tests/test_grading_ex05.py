"""Autograder of exercise ex05_diagnose: scores and feedback of the reference, the stub and common mistakes."""
import numpy as np
import pytest

from grading_harness import GradedSubmissions, full, q
from mutext_grader import ex05_diagnose as ex05

graded = GradedSubmissions("ex05_diagnose")


def test_reference_solution_scores_full_marks():
    rep = graded("reference")
    assert rep.max_score == 10
    assert rep.score == 10, rep.text()


def test_stub_scores_zero_without_crashing():
    rep = graded("stub")
    assert rep.score == 0
    assert all(x.status == "ok" for x in rep.questions)


def test_unwrapped_phase_is_named():
    rep = graded("ex05_unwrapped_phase")
    a = q(rep, "a")
    assert 0 < a.score < a.max_score
    assert "log of the ratio" in a.output
    assert full(rep, "b", "c", "d")


def test_zero_based_station_is_named():
    rep = graded("ex05_zero_based")
    d = q(rep, "d")
    assert d.score == pytest.approx(d.max_score / 4, abs=0.01)          # only the "none" case
    assert d.output.count("the station is 1-based") == 3


def test_hz_as_rad_s_is_named():
    rep = graded("ex05_hz_as_rad")
    b = q(rep, "b")
    assert b.score == 0 and "frequencies taken as rad/s" in b.output


def test_never_none_loses_the_none_case():
    rep = graded("ex05_never_none")
    d = q(rep, "d")
    assert d.score == pytest.approx(d.max_score * 3 / 4, abs=0.01)
    assert "there is no effect in these data" in d.output


def test_hidden_cases_are_detectable_and_distinct():
    """The data of (d) differ from the model by far more than the noise where there is an effect."""
    for label, example, kind, station, size, seed in ex05.D_CASES:
        M, C, K, forces, sensors = ex05.chain(example)
        f = ex05.grid(example)
        i, o = list(forces.values())[0], list(sensors.values())[0]
        h0 = ex05.response(M, C, K, f, i, o)
        h1 = ex05.response(M, C, K, f, i, o, (kind, station - 1, size))
        change = np.sqrt(np.mean(np.abs(np.log(h1 / h0)) ** 2))
        assert (change > 5 * ex05.NOISE) == (kind != "none"), label
