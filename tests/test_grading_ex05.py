"""Autograder of exercise ex05_diagnose: drawn inputs, scores and feedback of the reference, the stub,
common mistakes and submissions that do not solve.

On the inputs of one seed the reference solution is graded confined (tests/grading_harness.py: once,
in the background); the stub, the mistakes ``tests/grading_submissions/ex05_*.py`` and the trivial
submissions go through the same grader with their functions run in this process (confined, and the
reference on two more seeds, with ``-m slow``)."""
import re

import numpy as np
import pytest

from grading_harness import SUBS, Submissions, assert_same_scores_and_feedback, full, q
from mutext_grader import ex05_diagnose as ex05
from mutext_grader.compare import fmt

#: the seed of most checks: it draws one "none" case of four in (d), and no grounded spring at mass 1
SEED = 6
#: two more seeds for the reference solution (slow)
MORE_SEEDS = (1, 2)
TRIVIAL = ("ex05_always_none", "ex05_constant_effect", "ex05_model_only")

graded = Submissions("ex05_diagnose", SEED, extra={p.stem: p for p in (SUBS / "trivial").glob("ex05_*.py")})
PATHS = graded.paths
#: graded in this process by default, confined with -m slow
HERE = sorted(n for n in PATHS if n not in graded.confined)


def drawn(seed=SEED):
    return {x.id: x for x in ex05.questions(np.random.default_rng(seed))}


def d_keys(seed=SEED):
    return [c.key for c in drawn(seed)["d"].calls]


def test_the_default_seed_draws_a_none_case():
    kinds = [k[0] for k in d_keys()]
    assert kinds.count("none") == 1 and len(kinds) == ex05.N_D


def test_reference_solution_scores_full_marks():
    rep = graded("reference")
    assert rep.max_score == 10
    assert rep.score == 10, rep.text()
    assert f"seed {SEED}" in rep.inputs


@pytest.mark.slow
@pytest.mark.parametrize("seed", MORE_SEEDS)
def test_reference_solution_scores_full_marks_on_other_seeds(seed):
    rep = graded("reference", seed)
    assert rep.score == 10, rep.text()


@pytest.mark.slow
@pytest.mark.parametrize("name", HERE)
def test_confined_run_agrees_with_the_run_in_process(name):
    """What the default run checks on the functions run in this process holds for the confined run."""
    assert_same_scores_and_feedback(graded(name), graded.here(name))


@pytest.mark.slow
def test_reference_solution_is_right_on_many_draws():
    """In process, without the confined child: every question of 20 more draws scored in full."""
    from mutext_grader.solutions import ex05_diagnose as sol

    def payload(v):
        if np.isscalar(v):
            return float(v)
        v = np.asarray(v, float)
        return {"data": v.ravel().tolist(), "shape": list(v.shape)}
    for seed in range(100, 120):
        for question in ex05.questions(np.random.default_rng(seed)):
            fn = getattr(sol, question.function)
            outcomes = [{"ok": True, "value": payload(fn(*c.args, **c.kwargs))} for c in question.calls]
            score, fb = question.check(outcomes)
            assert score == pytest.approx(question.points), (seed, question.id, fb)


def test_stub_scores_zero_without_crashing():
    rep = graded.here("stub")
    assert rep.score == 0
    assert all(x.status == "ok" for x in rep.questions)


def test_unwrapped_phase_is_named():
    rep = graded.here("ex05_unwrapped_phase")
    a = q(rep, "a")
    assert 0 < a.score < a.max_score
    assert "log of the ratio" in a.output
    assert full(rep, "b", "c", "d")


def test_zero_based_station_is_named():
    """The stations one too low: no effect is found, so the "none" case does not count either."""
    rep = graded.here("ex05_zero_based")
    d = q(rep, "d")
    assert d.score == 0
    assert "the kind is right, the station is not" in d.output
    assert d.output.count("the stations are 1-based") == 1
    assert "score only when at least one hidden effect" in d.output


def test_hz_as_rad_s_is_named():
    rep = graded.here("ex05_hz_as_rad")
    b = q(rep, "b")
    assert b.score == 0 and "frequencies taken as rad/s" in b.output


def test_never_none_loses_the_none_cases():
    rep = graded.here("ex05_never_none")
    d = q(rep, "d")
    n_none = [k[0] for k in d_keys()].count("none")
    assert d.score == pytest.approx(d.max_score * (1 - n_none / ex05.N_D), abs=0.01)
    assert "20 sigma^2/2 (below it the answer is none)" in d.output


@pytest.mark.parametrize("name", TRIVIAL)
def test_submissions_that_do_not_solve_score_nothing(name):
    """Constants, inputs handed back and the model's own response earn nothing on (a)-(c); on (d) a
    constant kind and station earns only the cases it happens to match (none at this seed)."""
    rep = graded.here(name)
    assert all(x.status == "ok" for x in rep.questions)
    assert rep.score == 0, rep.text()


def test_always_none_scores_nothing_on_any_draw():
    """'none' everywhere: the "none" cases count only with an effect found, so (d) scores 0 whatever
    the draw (checked in-process on 20 draws)."""
    for seed in range(20):
        d = drawn(seed)["d"]
        outcomes = [{"ok": True, "value": {"data": [0.0, 0.0, 0.0], "shape": [3]}}] * len(d.calls)
        assert d.check(outcomes)[0] == 0


def test_constant_answers_score_little_over_many_draws():
    """Each constant (kind, station) on 100 draws: on average no more than chance, under 8 % of (d)."""
    keys = [[c[1:4] for c in ex05.d_cases(np.random.default_rng(seed))] for seed in range(100)]
    for kind in ex05.KINDS[1:]:
        for station in range(1, 5):
            total = 0.0
            for seed, ks in zip(range(100), keys):
                hits = sum(1 for k in ks if k[0] == kind and k[1] == station)
                total += hits * ex05.POINTS["d"] / ex05.N_D * 2 / 3     # the size part needs the size
            assert total / 100 < 0.08 * ex05.POINTS["d"], (kind, station)


def test_number_of_none_cases_is_drawn():
    counts = {[k[1] for k in ex05.d_cases(np.random.default_rng(s))].count("none") for s in range(30)}
    assert counts == set(range(ex05.MAX_NONE + 1))


def test_inputs_are_drawn_from_the_seed():
    """The same seed gives the same inputs (a regrade gives the same score); another seed others."""
    a, b, c = drawn(11), drawn(11), drawn(12)
    for qid in "abcd":
        assert [x.args for x in a[qid].calls] == [x.args for x in b[qid].calls]
        for x, y in zip(a[qid].calls, c[qid].calls):
            assert x.args != y.args, qid
    assert d_keys(11) != d_keys(12)


def test_feedback_names_no_hidden_parameter():
    """Wrong answers are described by what is right and what is not: no size, place or reference
    value of a hidden case is printed."""
    qs = drawn()
    for name in ("ex05_zero_based", "ex05_constant_effect", "ex05_model_only", "ex05_never_none"):
        rep = graded.here(name)
        text = rep.text()
        for call in qs["c"].calls:
            assert fmt(call.ref) not in text and f"{call.ref:g}" not in text
        for call in qs["a"].calls:
            assert fmt(call.ref) not in text
        for kind, station, size in d_keys():
            if kind != "none":
                assert fmt(size) not in text and f"{size:g}" not in text
        d = q(rep, "d").output
        assert not re.search(r"\b(mass|station|at)\s+\d", d), d
        for line in d.splitlines():
            assert not re.search(r"\d", re.sub(r"^\[case \d+ of \d+ \([a-z-]+ chain\)\]", "", line)
                                 .replace("20 sigma^2/2", "").replace("1-based", "").replace("10 %", "")
                                 .replace("(0, 1, 2 or 3)", "").replace("(the first mass is 1)", "")), line


def test_hidden_cases_are_detectable_and_well_determined():
    """The effects of (d) change the data by far more than the noise and the data fix their sizes
    far more tightly than the 10 % asked."""
    for seed in range(15):
        for example, kind, station, size, _ in ex05.d_cases(np.random.default_rng(seed)):
            if kind == "none":
                continue
            chans = ex05.d_channels(example)
            assert ex05.effect_strength(example, kind, station - 1, size, chans) >= ex05.MIN_STRENGTH
            assert ex05.size_spread(example, kind, station - 1, size, chans) <= 0.1 * ex05.RTOL_SIZE
