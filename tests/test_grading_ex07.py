"""Autograder of exercise ex07_small_gain: the reference M against the loop rebuilt with perturbed springs,
scores and feedback of the reference, the stub, common mistakes and submissions that do not solve.

The default run scores the submissions' functions in this process on one draw (the grader's checks are
the same functions the confined run feeds); the confined runs through ``grade`` are marked slow but the
reference's."""
import math
import re

import control as ct
import numpy as np
import pytest

from grading_harness import ROOT, SUBS, full, q
from grading_harness import drawn as _drawn
from grading_harness import scored_here
from mutext_grader import ex07_small_gain as ex07
from mutext_grader import grade
from mutext_grader.compare import fmt

EXERCISE = "ex07_small_gain"
SOLUTION = ROOT / "instructor" / "mutext_grader" / "solutions" / "ex07_small_gain.py"
SEED = 3
MISTAKES = ("ex07_negative_feedback", "ex07_hz", "ex07_shortcuts", "ex07_stretch")


def drawn(seed=SEED):
    return _drawn(EXERCISE, seed)


def scored(path, seed=SEED):
    """``{qid: (score, feedback text)}`` of a submission's functions run in this process
    (tests/grading_harness.py)."""
    return scored_here(EXERCISE, path, seed)


def test_reference_m_closes_to_the_loop_with_perturbed_springs():
    """Independent of the LFT: the poles of M's loop closed with w = diag(delta) z are those of the loop
    rebuilt from the springs k_i (1 + r_i delta_i), for several delta."""
    for call in drawn()["a"].calls:
        p = dict(zip(("m1", "m2", "k1", "k2", "r1", "r2"), call.args[:6]))
        K = call.args[6]["__ss__"]
        M = ex07.closed_loop(**p, K=K)
        A, B, C = (np.asarray(X, float) for X in (M.A, M.B, M.C))
        for delta in ([1.0, -1.0], [-0.7, 0.4], [0.3, 0.9]):
            via_lft = np.sort_complex(np.linalg.eigvals(A + B @ np.diag(delta) @ C))
            direct = np.sort_complex(ex07.perturbed_loop_poles(**p, K=K, delta=delta))
            assert np.allclose(via_lft, direct, rtol=1e-9, atol=1e-9)


def test_reference_norm_and_mu_against_independent_computations():
    """The grader's references (mutext.lti.hinf_norm, mutext.mu) against python-control's linfnorm
    (SLICOT AB13DD) and a brute-force phase and scaling search."""
    b = drawn()["b"]
    for call in b.calls:
        g, w = ct.linfnorm(ct.ss(*call.args[0]["__ss__"]))
        assert call.ref[0] == pytest.approx(g, rel=1e-6)
        assert call.ref[1] == pytest.approx(w, rel=1e-3)
    d = drawn()["d"]
    for call in d.calls:
        ref = ex07.mu_peaks(call.Ms)
        Ms = call.Ms
        k = int(np.argmax([np.linalg.norm(Mj, 2) for Mj in Ms]))
        th = np.linspace(-np.pi, np.pi, 721)
        U = np.zeros((th.size, 2, 2), complex)
        U[:, 0, 0], U[:, 1, 1] = np.exp(1j * th), 1.0
        brute = [np.abs(np.linalg.eigvals(Mj[None] @ U)).max() for Mj in Ms]
        assert max(brute) <= ref[1] * (1 + 1e-9) and max(brute) == pytest.approx(ref[1], rel=1e-4), k
        assert ref[0] == pytest.approx(ref[1], rel=1e-6)


def test_reference_solution_scores_full_marks_in_process():
    for qid, (score, fb) in scored(SOLUTION).items():
        assert score == pytest.approx(ex07.POINTS[qid]), (qid, fb)


def test_reference_solution_scores_full_marks_confined():
    rep = grade("ex07_small_gain", SOLUTION, 60.0, seed=SEED)
    assert rep.max_score == 10 and rep.score == 10, rep.text()


@pytest.mark.slow
@pytest.mark.parametrize("seed", (1, 2, 5, 8))
def test_reference_solution_on_other_draws(seed):
    for qid, (score, fb) in scored(SOLUTION, seed).items():
        assert score == pytest.approx(ex07.POINTS[qid]), (seed, qid, fb)


def test_negative_feedback_is_named():
    s = scored(SUBS / "ex07_negative_feedback.py")
    assert s["a"][0] == 0 and "u = -K y" in s["a"][1]
    assert all(s[i][0] == ex07.POINTS[i] for i in "bcd")


def test_hz_is_named():
    s = scored(SUBS / "ex07_hz.py")
    assert s["b"][0] == pytest.approx(0.6 * ex07.POINTS["b"]) and "in Hz" in s["b"][1]
    assert s["c"][0] == 0 and "rad/s" in s["c"][1]
    assert s["a"][0] == ex07.POINTS["a"] and s["d"][0] == ex07.POINTS["d"]


def test_shortcuts_are_named_and_earn_nothing():
    s = scored(SUBS / "ex07_shortcuts.py")
    assert s["a"][0] == ex07.POINTS["a"]
    assert s["b"][0] <= 0.4 * ex07.POINTS["b"] and "too low" in s["b"][1]
    assert s["c"][0] == 0 and "I/lambda" in s["c"][1]
    assert s["d"][0] == 0 and "spectral radius" in s["d"][1] and "without scaling" in s["d"][1]


def test_stretch_and_transposed_delta_are_named():
    s = scored(SUBS / "ex07_stretch.py")
    assert s["a"][0] == 0 and "stretch" in s["a"][1]
    assert s["c"][0] == 0 and "transposed" in s["c"][1]
    assert s["b"][0] == ex07.POINTS["b"] and s["d"][0] == ex07.POINTS["d"]


def test_submission_that_does_not_solve_scores_nothing():
    s = scored(SUBS / "trivial" / "ex07_constants.py")
    assert sum(v[0] for v in s.values()) == 0, s


def test_feedback_names_no_reference_value():
    qs = drawn()
    refs = [c.ref[0] for c in qs["b"].calls] + [c.ref[1] for c in qs["b"].calls] + \
           [c.smax for c in qs["c"].calls]
    for name in MISTAKES:
        text = "\n".join(fb for _, fb in scored(SUBS / f"{name}.py").values())
        for r in refs:
            assert fmt(r) not in text and f"{r:g}" not in text and f"{1 / r:g}" not in text, (name, r)
        for line in text.splitlines():
            body = re.sub(r"^\[system \d of \d\]", "", line)
            body = body.replace("1e-03", "").replace("1 %", "").replace("-1", "").replace("2 pi", "")
            body = re.sub(r"\b(b_i|r_i|k_i|u_1|v_1|sigma_1|w1|w2|z1|z2|\d of 4)\b", "", body)
            assert not re.search(r"\d\.\d", body), line


@pytest.mark.slow
def test_inputs_are_drawn_from_the_seed():
    a = ex07.questions(np.random.default_rng(11))
    b = ex07.questions(np.random.default_rng(11))
    c = ex07.questions(np.random.default_rng(12))
    assert [x.args for x in a[0].calls] == [x.args for x in b[0].calls]
    assert all(x.args != y.args for x, y in zip(a[0].calls, c[0].calls))


def _apart(systems):
    for p, K in systems:
        M = ex07.closed_loop(**p, K=K)
        Ms = ex07._response_stack(M, ex07.d_grid(M))
        lo, up = ex07.mu_peaks(Ms)
        yield M, Ms, lo, up


def test_drawn_systems_keep_the_shortcuts_apart():
    """On the draw of the other tests sigma_max lies above mu and the spectral radius below; the slow run
    checks more draws."""
    cases = []
    for a, d in zip(drawn()["a"].calls, drawn()["d"].calls):
        p = dict(zip(("m1", "m2", "k1", "k2", "r1", "r2"), a.args[:6]))
        lo, up = ex07.mu_peaks(d.Ms)
        cases.append((ex07.closed_loop(**p, K=a.args[6]["__ss__"]), d.Ms, lo, up))
    _check_apart(cases)


@pytest.mark.slow
def test_drawn_systems_keep_the_shortcuts_apart_on_more_draws():
    for seed in range(10, 16):
        _check_apart(_apart(ex07._draw(np.random.default_rng(seed))))


def _check_apart(cases):
    for M, Ms, lo, up in cases:
        assert max(np.linalg.norm(Mj, 2) for Mj in Ms) > (1 + ex07.DISTINCT) * up
        assert max(np.abs(np.linalg.eigvals(Mj)).max() for Mj in Ms) < (1 - ex07.DISTINCT_RHO) * lo
        assert np.linalg.eigvals(np.asarray(M.A, float)).real.max() < 0
        assert math.isfinite(up)


@pytest.mark.slow
def test_confined_runs_stub_and_blocked_import():
    stub = grade("ex07_small_gain", ROOT / "exercises" / "ex07_small_gain.py", 60.0, seed=SEED)
    assert stub.score == 0 and all(x.status == "ok" for x in stub.questions)
    cheat = grade("ex07_small_gain", SUBS / "ex07_cheat_mu.py", 60.0, seed=SEED)
    d = q(cheat, "d")
    assert d.score == 0 and d.status == "violation" and "mutext.mu" in d.output
    assert full(cheat, "a", "b", "c")
