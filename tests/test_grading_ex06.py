"""Autograder of exercise ex06_sidebands: scores and feedback of the reference, the stub and common mistakes."""
import numpy as np
import pytest
from grading_harness import GradedSubmissions, full, q

from mutext_grader import ex06_sidebands as ex06

graded = GradedSubmissions("ex06_sidebands")


def test_reference_solution_scores_full_marks():
    rep = graded("reference")
    assert rep.max_score == 10
    assert rep.score == 10, rep.text()


def test_stub_scores_zero_without_crashing():
    rep = graded("stub")
    assert rep.score == 0
    assert all(x.status == "ok" for x in rep.questions)


def test_speed_in_rad_per_s_is_named():
    rep = graded("ex06_rad_per_s")
    a = q(rep, "a")
    assert a.score == 0
    assert "speed taken in rad/s" in a.output
    assert full(rep, "b", "c")


def test_centre_in_the_fit_is_named():
    rep = graded("ex06_centre_in_fit")
    b = q(rep, "b")
    assert b.score <= 0.5            # at most the detector's half point: every size is off
    assert "centre points in the fit" in b.output
    assert full(rep, "a", "c")


def test_fixed_threshold_fails_the_noisier_sweeps():
    rep = graded("ex06_fixed_threshold")
    c = q(rep, "c")
    noisy = [case for case in ex06.C_CASES if case[2] > ex06.NOISE]
    assert c.score == pytest.approx(c.max_score * (1 - len(noisy) / len(ex06.C_CASES)), abs=0.01)
    assert "proportional to the noise" in c.output
    assert full(rep, "a", "b")


def test_blocked_modules():
    """The modules that make the sweeps or find sidebands cannot be imported by a submission."""
    for m in ("mutext.diagnose", "mutext.rotor", "mutext.rig"):
        assert m in ex06.EXERCISE.blocked_modules


def test_sweeps_differ_by_their_sidebands_not_by_noise():
    """At the breathing crack's 1X sideband the detector sees far more than the noise; on the healthy
    rotor at the same frequency, no more than the noise (the premise of (b) and (c))."""
    fc = ex06.B_CASES[0][4]
    f, h = ex06.sweep("breathing", ex06.LOW_NOISE, 61)
    g, h0 = ex06.sweep("healthy", ex06.LOW_NOISE, 62)
    assert np.array_equal(f, g)
    cracked, healthy = ex06.size(f, h, fc, 3.0), ex06.size(g, h0, fc, 3.0)
    assert cracked > 20 * ex06.LOW_NOISE
    assert healthy < 5 * ex06.LOW_NOISE
    # a baseline fitted to H itself would not tell them apart
    assert ex06.size(g, h0, fc, 3.0, invert=False) > 0.5 * ex06.size(f, h, fc, 3.0, invert=False)


def test_candidates_formula():
    c = ex06.candidates([30.0, 50.0], 10.0, [1, 2], 20.0, 60.0)
    assert c.tolist() == [20.0, 30.0, 40.0, 50.0, 60.0]   # 40 from both modes, once; 20 and 60 on the edges


def test_sweeps_are_those_of_measure_rotor():
    """A cached sweep with its noise is bit for bit what measure_rotor gives for the same seed."""
    from mutext.rig import measure_rotor
    f, h = ex06.sweep("bearings", ex06.NOISE, 76)
    d = measure_rotor(ex06.model("bearings"), "i12", "x13", noise=ex06.NOISE, rng=76)
    assert np.array_equal(f, d.freq_hz) and np.array_equal(h, d.response)


def test_frequencies_of_the_grader_are_the_models():
    """The natural frequencies given to students and the candidates of (b) come from the models."""
    healthy = ex06.model("healthy").natural_frequencies(n=8)
    assert np.allclose(ex06.HEALTHY_HZ, healthy, rtol=0, atol=1e-4)
    first = {name: ex06.model(name).natural_frequencies(n=3) for name in ("breathing", "open", "bearings")}
    assert ex06.B_CASES[0][4] == round(first["breathing"][0] + ex06.SPEED_HZ, 2)     # k = -1
    assert ex06.B_CASES[2][4] == round(first["open"][0] + 2 * ex06.SPEED_HZ, 2)      # k = -2
    assert ex06.B_CASES[3][4] == round(first["bearings"][2] - ex06.SPEED_HZ, 2)      # k = +1, second pair
