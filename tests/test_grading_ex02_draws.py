"""ex02 with inputs drawn per run: full marks on several seeds, different inputs for different seeds,
nothing for trivial, constant, random and library one-liner answers, no reference value in the feedback.

The checks run in this process on the questions of a seed; one trivial submission goes through the
grader with its functions run in this process (tests/grading_harness.py); it and the reference on three
seeds go through the confined child only when slow (each run costs seconds; ex02 is graded confined in
tests/test_grading_ex02.py).
"""

import numpy as np
import pytest

import grading_harness as harness
from grading_harness import ROOT, SUBS, load, q
from mutext_grader import ex02_mu as ex02
from mutext_grader.solutions import ex02_mu as sol
from test_grading_ex01_draws import leaks, scores

EXERCISE = "ex02_mu"
REFERENCE = ROOT / "instructor" / "mutext_grader" / "solutions" / f"{EXERCISE}.py"
TRIVIAL = SUBS / "trivial"
SEEDS = (21, 22, 23)

def graded(path, seed):
    """The report of ``path`` graded confined on the inputs of ``seed`` (tests/grading_harness.py: once)."""
    return harness.graded(EXERCISE, path, seed)


def _questions(seed):
    return ex02.questions(np.random.default_rng(seed))


def test_two_seeds_draw_different_inputs_and_one_seed_the_same():
    one = {x.id: [c.args for c in x.calls] for x in _questions(1)}
    two = {x.id: [c.args for c in x.calls] for x in _questions(2)}
    for qid in one:
        for c1, c2 in zip(one[qid], two[qid]):
            assert c1 != c2, qid
    assert {x.id: [c.args for c in x.calls] for x in _questions(1)} == one
    labels = [c.label for x in _questions(1) for c in x.calls]
    assert all(lab.startswith(("matrix ", "parameter set ", "2x2 response", "3x3 response")) for lab in labels)


def test_draws_keep_the_cases_kinds_and_keep_mistakes_apart():
    for seed in range(6):
        d = ex02._draw(np.random.default_rng(seed))
        M = d["a2"][0][1]
        assert np.linalg.matrix_rank(M) == 1 and not M.imag.any()      # example 8.5 stays rank-one
        for _, M in d["a1"]:
            assert ex02._ok_full(M)
        for _, M in d["a2"]:
            assert ex02._ok_scalar(M, False)
        for _, M in d["b"]:
            assert ex02.mu_upper_ref(M) >= ex02.TRIVIAL_GAP * ex02._trivial_delta(M)
        for _, Ms in d["d"]:
            assert Ms.shape[0] == 40 and ex02._ok_sweep(Ms)


def test_prepare_computes_the_references_of_the_same_draws():
    ex02.prepare(np.random.default_rng(9))
    info = ex02._upper_cached.cache_info()
    for _, Ms in ex02._draw(np.random.default_rng(9))["d"]:
        ex02.peak_ref(Ms)
    assert ex02._upper_cached.cache_info().misses == info.misses


@pytest.mark.parametrize("seed", SEEDS)
def test_reference_scores_full_marks_in_process(seed):
    for qid, (score, fb) in scores(sol, _questions(seed), only=("a1", "a2", "b", "c")).items():
        assert score == ex02.POINTS[qid], (seed, qid, fb)


@pytest.mark.parametrize("name", ["ex02_trivial_delta", "ex02_constants", "ex02_random"])
def test_trivial_submissions_earn_nothing_in_process(name):
    mod = load(TRIVIAL / f"{name}.py")
    for seed in SEEDS[:2]:
        res = scores(mod, _questions(seed))
        assert {qid: s for qid, (s, _) in res.items()} == {qid: 0 for qid in res}, (seed, res)


@pytest.mark.slow
def test_ex02_trivial_delta_confined_agrees_with_the_run_in_process():
    """The default run grades ``ex02_trivial_delta.py`` with its functions run in this process; confined, the same."""
    path = TRIVIAL / "ex02_trivial_delta.py"
    harness.assert_same_scores_and_feedback(graded(path, SEEDS[0]), harness.graded_here(EXERCISE, path, SEEDS[0]))


def test_trivial_delta_graded_scores_zero():
    rep = harness.graded_here(EXERCISE, TRIVIAL / "ex02_trivial_delta.py", SEEDS[0])
    assert rep.score == 0, rep.text()
    assert "diag(1/M_11, 0, ...)" in q(rep, "b").output


def _arr(x):
    x = np.asarray(x, dtype=float)
    return {"ok": True, "value": {"shape": list(x.shape), "data": x.ravel().tolist()}}


def test_delta_scores_between_trivial_and_optimal():
    qb = next(x for x in _questions(SEEDS[1]) if x.id == "b")
    cases = ex02._draw(np.random.default_rng(SEEDS[1]))["b"]

    best = [_arr(np.stack(sol.destabilizing_delta(M.real, M.imag))) for _, M in cases]
    assert qb.check(best)[0] == ex02.POINTS["b"]
    # the identity over the largest eigenvalue of M, and diag(1/M_ii) at the largest diagonal entry
    triv = []
    for _, M in cases:
        lam = np.linalg.eigvals(M)
        D = np.eye(len(M)) / lam[np.argmax(abs(lam))]
        triv.append(_arr(np.stack([D.real, D.imag])))
    assert qb.check(triv)[0] == 0
    one = []
    for _, M in cases:
        i = int(np.argmax(abs(np.diag(M))))
        D = np.zeros(M.shape, complex)
        D[i, i] = 1 / M[i, i]
        one.append(_arr(np.stack([D.real, D.imag])))
    assert qb.check(one)[0] == 0
    # a huge array is refused by its shape, before its data are read
    score, fb = qb.check([{"ok": True, "value": {"shape": [2, 400, 400], "data": []}}] * len(cases))
    assert score == 0 and all("got shape (2, 400, 400)" in line for line in fb)


def test_feedback_on_wrong_answers_prints_no_reference_number():
    seed = SEEDS[2]
    qs = _questions(seed)
    d = ex02._draw(np.random.default_rng(seed))

    class Wrong:
        @staticmethod
        def mu_full(r, i):
            return 1.13 * sol.mu_full(r, i)

        @staticmethod
        def mu_scalar_blocks_upper(r, i):
            M = np.asarray(r) + 1j * np.asarray(i)
            return 0.95 * ex02.mu_upper_ref(M)

        @staticmethod
        def destabilizing_delta(r, i):
            Dr, Di = sol.destabilizing_delta(r, i)
            return 1.3 * Dr, 1.3 * Di        # not singular any more

        @staticmethod
        def uncertain_spring_lft(m, k, rel):
            return sol.uncertain_spring_lft(m, k, 0.5 * rel)

        @staticmethod
        def mu_peak(r, i):
            Ms = np.asarray(r) + 1j * np.asarray(i)
            return 0.9 * ex02.peak_ref(Ms)

    res = scores(Wrong, qs)
    assert all(s == 0 for s, _ in res.values()), res
    numbers = [float(np.linalg.norm(M, 2)) for _, M in d["a1"]]
    numbers += [ex02.mu_upper_ref(M) for _, M in d["a2"]] + [ex02.mu_lower_ref(M) for _, M in d["b"]]
    numbers += [x for p in d["c"] for x in p] + [ex02.peak_ref(Ms) for _, Ms in d["d"]]
    fb = [line for _, lines in res.values() for line in lines]
    assert not leaks(fb, numbers), (leaks(fb, numbers), fb)
    assert any("too low" in line for line in res["a2"][1])


@pytest.mark.slow
@pytest.mark.parametrize("seed", SEEDS)
def test_reference_scores_full_marks_graded(seed):
    rep = graded(REFERENCE, seed)
    assert rep.score == 10, rep.text()


@pytest.mark.slow
@pytest.mark.parametrize("name", ["ex02_constants", "ex02_random"])
def test_trivial_submissions_graded_score_zero(name):
    rep = graded(TRIVIAL / f"{name}.py", SEEDS[1])
    assert rep.score == 0, rep.text()
