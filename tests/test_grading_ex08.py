"""Autograder of exercise ex08_mbi: the reference plant against the rigs rebuilt from M, C, K, scores and
feedback of the reference, the stub, common mistakes and submissions that do not solve.

The default run scores (a) and (d) (no D-K) in this process on one draw and checks (c)'s answers that
need no search; everything that runs D-K ((b), (c) of the reference and of the mistakes, the confined
runs through ``grade``) is marked slow."""
import re

import control as ct
import numpy as np
import pytest

from grading_harness import ROOT, SUBS, full, q
from grading_harness import drawn as _drawn
from grading_harness import scored_here
from mutext_grader import ex08_mbi as ex08
from mutext_grader import grade
from mutext_grader.compare import fmt

EXERCISE = "ex08_mbi"
SOLUTION = ROOT / "instructor" / "mutext_grader" / "solutions" / "ex08_mbi.py"
SEED = 1
CHEAP = ("a", "d")


def drawn(seed=SEED):
    return _drawn(EXERCISE, seed)


def scored(path, qids=CHEAP, seed=SEED):
    """``{qid: (score, feedback text)}`` of a submission's functions run in this process
    (tests/grading_harness.py)."""
    return scored_here(EXERCISE, path, seed, qids)


def _direct(rig, delta, Wz, w):
    """``(x_t - x_e) / Wz`` per unit ``w`` by direct solves of ``K - w^2 M + j w C`` (no state space, no LFT)."""
    def solve(values, i, o):
        v = dict(zip(ex08.PARAMS, values))
        M, C, K = ex08._matrices(v)
        e = np.zeros(3)
        e[i] = 1.0
        return np.array([np.linalg.solve(K - wi * wi * M + 1j * wi * C, e)[o] for wi in w])
    t = list(rig["true"])
    i = ex08.PARAMS.index(rig["changed"])
    t[i] *= 1 + rig["rel"] * delta
    exc, meas = rig["excitation"], rig["measurement"]
    return (solve(t, exc, meas) - solve(rig["engineering"], exc, meas)) * rig["Ww"] / Wz


def test_reference_plant_against_direct_solves():
    """The reference plant closed with w_unc = delta z_unc: its w -> z channel is the error of the rig
    rebuilt with p0 (1 + rel delta), its u -> y channel minus the engineering receptance at the control cart."""
    for call in drawn()["a"].calls:
        rig, Wz = call.args
        P = ex08.reference_plant(rig, Wz).P
        w = np.logspace(-0.5, 2.2, 37)
        for delta in (-1.0, 0.4, 1.0):
            H = ct.ss(ex08.closed_channels(P, delta))(1j * w)
            assert np.allclose(H[0, 0], _direct(rig, delta, Wz, w), rtol=1e-7, atol=0)
        v = dict(zip(ex08.PARAMS, rig["engineering"]))
        M, C, K = ex08._matrices(v)
        c = rig["control"]
        rec = np.array([np.linalg.inv(K - wi * wi * M + 1j * wi * C)[c, c] for wi in w])
        assert np.allclose(ct.ss(ex08.closed_channels(P, 0.0))(1j * w)[2, 2], -rec, rtol=1e-7, atol=0)
        assert P.D[2, 3] == rig["eps_u"] and P.D[3, 2] == rig["eps_y"]


def test_d_reference_reads_the_drawn_change():
    """The K of (d) is D_u rolled off above its band: the reference fit on the band reads D_u's size within
    the roll-off's few percent, and the fit over the whole grid (the named mistake) is far off."""
    for seed in (SEED, 4):
        c = drawn(seed)["d"].calls[0]
        d = ex08.du(c.args[0])
        key = max(d, key=lambda k: abs(d[k]))
        got = {"dm": c.fit.dm, "dc": c.fit.dc, "dk": c.fit.dk}[key]
        assert got == pytest.approx(d[key], rel=0.06)
        whole = dict(zip(("dm", "dc", "dk"), c.whole))[key]
        assert abs(whole / d[key] - 1) > 0.1


def test_reference_solution_scores_a_and_d_in_process():
    for qid, (score, fb) in scored(SOLUTION).items():
        assert score == pytest.approx(ex08.POINTS[qid]), (qid, fb)


@pytest.mark.slow
@pytest.mark.parametrize("seed", (2, 3))
def test_reference_solution_scores_a_and_d_on_other_draws(seed):
    for qid, (score, fb) in scored(SOLUTION, seed=seed).items():
        assert score == pytest.approx(ex08.POINTS[qid]), (seed, qid, fb)


def test_plus_u_is_named():
    s = scored(SUBS / "ex08_plus_u.py")
    assert s["a"][0] < ex08.POINTS["a"] and "+u" in s["a"][1]


def test_z_not_divided_by_wz_is_named():
    s = scored(SUBS / "ex08_no_wz.py")
    assert s["a"][0] < ex08.POINTS["a"] and "not divided by Wz" in s["a"][1]
    assert s["d"][0] < ex08.POINTS["d"]


def test_whole_grid_fit_is_named():
    s = scored(SUBS / "ex08_whole_grid.py")
    assert s["a"][0] == ex08.POINTS["a"]
    assert s["d"][0] == 0 and "whole grid" in s["d"][1]


def test_bracket_ends_and_constants_score_nothing():
    """The ends of (c)'s bracket (no search), a zero plant, no controller and a zero fit earn nothing; (c)
    is decided by the floor and the window alone, without D-K."""
    s = scored(SUBS / "trivial" / "ex08_bracket.py", ("a", "d"))
    assert s["a"][0] == 0 and s["d"][0] == 0
    c = drawn()["c"]
    lo, hi = c.calls[0].args[1:3]
    fl = c.calls[0].floor
    assert lo < fl and hi > 2.5 * fl and np.sqrt(lo * hi) > 1.5 * fl and (lo + hi) / 2 > 1.5 * fl


def test_c_window_is_above_the_floor_for_every_draw():
    """The bracket of (c) never puts an end or a mean of it in the accepted window (floor to 1.15 times the
    reference, which is at most 1.1 times the floor times 1.3 from the secant steps)."""
    rng = np.random.default_rng(0)
    for _ in range(2000):
        fl = 1.0
        lo, hi = ex08._bracket(rng, fl)
        assert lo < 0.95 * fl
        assert min(hi, np.sqrt(lo * hi), (lo + hi) / 2) > 1.55 * fl


def test_feedback_names_no_reference_value():
    c = drawn()["d"].calls[0]
    refs = [c.fit.dm, c.fit.dc, c.fit.dk]
    for name in ("ex08_plus_u", "ex08_no_wz", "ex08_whole_grid"):
        text = "\n".join(fb for _, fb in scored(SUBS / f"{name}.py").values())
        for r in refs:
            assert fmt(r) not in text and f"{r:g}" not in text, (name, r)
        for line in text.splitlines():
            body = re.sub(r"^\[(rig \d of 2|trial \w+-like rig)\]", "", line)
            assert not re.search(r"\d\.\d", body), line


def test_inputs_are_drawn_from_the_seed():
    a, b, c = (ex08._draw(np.random.default_rng(s)) for s in (11, 11, 12))
    assert a["rig"] == b["rig"] and a["a"] == b["a"] and a["bracket"] == b["bracket"]
    assert a["a"] != c["a"]


@pytest.mark.slow
def test_reference_solution_scores_full_marks_confined():
    rep = grade("ex08_mbi", SOLUTION, 60.0, seed=SEED)
    assert rep.max_score == 10 and rep.score == 10, rep.text()


@pytest.mark.slow
def test_b_and_c_of_the_reference_and_the_mistakes_in_process():
    s = scored(SOLUTION, ("b", "c"))
    assert s["b"][0] == ex08.POINTS["b"] and s["c"][0] == ex08.POINTS["c"], s
    s = scored(SUBS / "ex08_plus_u.py", ("b",))
    assert s["b"][0] < 1.0 and ("unstable" in s["b"][1] or "mu upper bound" in s["b"][1]
                                or "opposite sign" in s["b"][1]), s


@pytest.mark.slow
def test_confined_runs_of_the_stub_and_submissions_that_do_not_solve():
    stub = grade("ex08_mbi", ROOT / "exercises" / "ex08_mbi.py", 60.0, seed=SEED)
    assert stub.score == 0 and all(x.status == "ok" for x in stub.questions)
    for name in ("ex08_bracket", "ex08_low_end"):
        rep = grade("ex08_mbi", SUBS / "trivial" / f"{name}.py", 60.0, seed=SEED)
        assert rep.score == 0, rep.text()
    low = grade("ex08_mbi", SUBS / "trivial" / "ex08_low_end.py", 60.0, seed=SEED)
    assert "below the floor" in q(low, "c").output
    hi = grade("ex08_mbi", SUBS / "trivial" / "ex08_bracket.py", 60.0, seed=SEED)
    assert "upper end of the bracket" in q(hi, "c").output
    assert not full(hi, "b")
