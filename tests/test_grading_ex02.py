"""Autograder of exercise ex02_mu: scores, feedback, integrity (mutext.mu, mutext.uncertain, mutext.dk blocked).

On the inputs of one seed the reference solution and the submission that imports mutext.mu are graded
confined (tests/grading_harness.py: once, in the background); the stub and the other submissions
``tests/grading_submissions/ex02_*.py`` go through the same grader with their functions run in this
process (confined with ``-m slow``); the diagnoses are also checked in-process on constructed answers.
"""

import numpy as np
import pytest

from grading_harness import ROOT, Submissions, assert_same_scores_and_feedback, full, q
from mutext import cli
from mutext_grader import ex02_mu as ex02
from mutext_grader.solutions import ex02_mu as sol

EXERCISE = "ex02_mu"
SP = np.array([[2.0, 2.0], [-1.0, -1.0]])     # Skogestad & Postlethwaite, example 8.5
SEED = 20240611
graded = Submissions(EXERCISE, SEED, confined=("reference", "ex02_cheat_mu"))
SUBMISSIONS = graded.paths
#: graded in this process by default, confined with -m slow
HERE = sorted(n for n in SUBMISSIONS if n not in graded.confined)


# ----------------------------------------------------------------------------
# graded submissions
# ----------------------------------------------------------------------------

def test_reference_solution_scores_full_marks():
    rep = graded("reference")
    assert rep.max_score == 10 and [x.max_score for x in rep.questions] == [1, 2, 2, 3, 2]
    assert rep.score == 10, rep.text()
    assert all(x.output.startswith("correct") for x in rep.questions)


def test_stub_scores_zero_without_crashing():
    rep = graded.here("stub")
    assert rep.score == 0
    for x in rep.questions:
        assert x.status == "ok"
        assert x.output.count("not implemented yet") == 1


def test_spectral_radius_and_unscaled_norms_are_named():
    rep = graded.here("ex02_spectral_radius")
    assert q(rep, "a1").score == 0
    assert "returned the spectral radius max|eig(M)|, not the largest singular value" in q(rep, "a1").output
    assert q(rep, "a2").score == 0 and "no D-scaling: this is sigma_max(M)" in q(rep, "a2").output
    b = q(rep, "b")
    assert b.score == 0 and "Delta is not diagonal" in b.output and "v u^H / sigma_1" in b.output
    assert full(rep, "c")
    assert q(rep, "d").score == 0 and "peak of sigma_max(M(jw))" in q(rep, "d").output
    assert rep.score == 3


def test_dmd_and_sign_mistakes_are_named():
    rep = graded.here("ex02_dmd_sign")
    assert full(rep, "a1", "d")
    a2 = q(rep, "a2")
    # the same diagnosis for every matrix is said once
    assert a2.score == 0 and a2.output.count("D applied as D M D instead of D M D^-1") == 1, rep.text()
    assert q(rep, "b").score == 0 and "I + M Delta is singular, not I - M Delta" in q(rep, "b").output
    assert q(rep, "c").score == 0 and "the LFT closes with the wrong sign" in q(rep, "c").output
    assert rep.score == 3


def test_crude_numerics_earn_nothing():
    rep = graded.here("ex02_crude")
    a1 = q(rep, "a1")
    assert a1.score == 0, rep.text()         # a1's matrices all have rank two: Frobenius > sigma_max
    assert a1.output.count("returned the Frobenius norm") == 1   # said once for the four
    a2 = q(rep, "a2")
    assert a2.score < 2 and ("did not converge" in a2.output or "no D-scaling" in a2.output)
    b = q(rep, "b")                          # Delta = I / lambda(M): found without a search
    assert b.score == 0 and b.output.count("no smaller than a perturbation found without any search") == 3
    c = q(rep, "c")
    assert c.score == 0 and "the size rel is missing" in c.output
    assert q(rep, "d").score == 0 and "take the largest bound over all 40 frequencies" in q(rep, "d").output
    assert rep.score == a2.score


def test_importing_mutext_mu_is_blocked():
    rep = graded("ex02_cheat_mu")
    a2 = q(rep, "a2")
    assert a2.score == 0 and a2.status == "violation" and "importing mutext.mu" in a2.output
    assert full(rep, "a1", "c")              # c uses another valid scaling of w and z
    assert rep.score == 4


def test_every_wrong_submission_scores_less():
    for name in SUBMISSIONS:
        if name.startswith("ex02_"):
            assert (graded(name) if name in graded.confined else graded.here(name)).score < 10, name


@pytest.mark.slow
@pytest.mark.parametrize("name", HERE)
def test_confined_run_agrees_with_the_run_in_process(name):
    """What the default run checks on the functions run in this process holds for the confined run."""
    assert_same_scores_and_feedback(graded(name), graded.here(name))


# ----------------------------------------------------------------------------
# references and diagnoses, in-process
# ----------------------------------------------------------------------------

def _float(x):
    return {"ok": True, "value": float(x)}


def _arr(x):
    x = np.asarray(x, dtype=float)
    return {"ok": True, "value": {"shape": list(x.shape), "data": x.ravel().tolist()}}


def _ss(A, B, C, D):
    return {"ok": True, "value": {"A": np.asarray(A).tolist(), "B": np.asarray(B).tolist(),
                                  "C": np.asarray(C).tolist(), "D": np.asarray(D).tolist(), "dt": 0}}


def _question(qid, seed=SEED):
    return next(x for x in ex02.questions(np.random.default_rng(seed)) if x.id == qid)


def _check(qid, answer, wrap):
    qu = _question(qid)
    return qu.check([wrap(answer(*c.args, **c.kwargs)) for c in qu.calls])


def test_textbook_example_values():
    M = SP
    assert abs(sol.mu_full(M.real, M.imag) - np.sqrt(10)) < 1e-12
    assert abs(sol.mu_scalar_blocks_upper(M.real, M.imag) - 3.0) < 1e-6
    assert abs(ex02.mu_upper_ref(M) - 3.0) < 1e-6
    Dr, Di = sol.destabilizing_delta(M.real, M.imag)
    D = Dr + 1j * Di
    assert abs(np.linalg.det(np.eye(2) - M @ D)) < 1e-9 and abs(np.linalg.norm(D, 2) - 1 / 3) < 1e-6


@pytest.mark.slow     # the default run: test_reference_solution_scores_full_marks, the same on the same seed, confined
def test_full_marks_in_process():
    for qid, fn, wrap in (("a1", sol.mu_full, _float), ("a2", sol.mu_scalar_blocks_upper, _float),
                          ("b", sol.destabilizing_delta, _arr), ("c", sol.uncertain_spring_lft, lambda v: _ss(*v)),
                          ("d", sol.mu_peak, _float)):
        score, fb = _check(qid, fn, wrap)
        assert score == ex02.POINTS[qid], fb
        assert fb[0].startswith("correct")


@pytest.mark.parametrize("answer, text", [
    (lambda r, i: np.linalg.norm(np.asarray(r) + 1j * np.asarray(i), 2) ** 2, "sigma_max^2"),
    (lambda r, i: np.linalg.svd(np.asarray(r) + 1j * np.asarray(i), compute_uv=False)[-1], "smallest singular"),
    (lambda r, i: np.linalg.norm(np.asarray(r), 2), "real part of M only"),
])
def test_full_block_diagnoses(answer, text):
    score, fb = _check("a1", answer, _float)
    assert score < ex02.POINTS["a1"] and any(text in line for line in fb), fb


def test_delta_diagnoses():
    def inverse(r, i):                       # U lambda instead of U / lambda
        Dr, Di = sol.destabilizing_delta(r, i)
        d = 1.0 / np.diag(Dr + 1j * Di)
        return np.diag(d).real, np.diag(d).imag

    score, fb = _check("b", inverse, _arr)
    assert score == 0 and any("I - M Delta^-1 is singular" in line for line in fb), fb

    score, fb = _check("b", lambda r, i: (0.1 * np.eye(len(r)), np.zeros((len(r), len(r)))), _arr)
    assert score == 0 and all("I - M Delta is not singular" in line for line in fb), fb

    def diagonals(r, i):                     # the diagonals only, shape (2, n): accepted
        Dr, Di = sol.destabilizing_delta(r, i)
        return np.diag(Dr), np.diag(Di)

    score, fb = _check("b", diagonals, _arr)
    assert score == ex02.POINTS["b"], fb
    score, fb = _question("b").check([_arr(np.zeros(3))] * 3)
    assert score == 0 and any("shape (2, 2, 2)" in line for line in fb)


def test_lft_diagnoses():
    def lower_order(m, k, rel):
        A, B, C, D = sol.uncertain_spring_lft(m, k, rel)
        return A, B[:, ::-1], C[::-1], D

    score, fb = _check("c", lower_order, lambda v: _ss(*v))
    assert score == 0 and any("lower-LFT order" in line for line in fb), fb

    def wrong_mass(m, k, rel):
        return sol.uncertain_spring_lft(2 * m, k, rel)

    score, fb = _check("c", wrong_mass, lambda v: _ss(*v))
    assert score == 0 and any("nominal model" in line for line in fb), fb

    def feedthrough(m, k, rel):
        A, B, C, D = sol.uncertain_spring_lft(m, k, rel)
        D = D.copy()
        D[0, 0] = 0.3
        return A, B, C, D

    score, fb = _check("c", feedthrough, lambda v: _ss(*v))
    assert score == 0 and any("nonlinearly" in line for line in fb), fb

    score, fb = _question("c").check([_ss(np.zeros((1, 1)), np.zeros((1, 1)), np.zeros((1, 1)),
                                          np.zeros((1, 1)))] * 2)
    assert score == 0 and any("2 inputs [w, f] and 2 outputs [z, x]" in line for line in fb)


def test_peak_diagnoses():
    def first(r, i):
        M = np.asarray(r)[0] + 1j * np.asarray(i)[0]
        return ex02.mu_upper_ref(M)

    score, fb = _check("d", first, _float)
    assert score == 0 and all("first frequency" in line for line in fb), fb


def test_listed_and_stub_named():
    assert ex02.EXERCISE.stub == "exercises/ex02_mu.py"
    assert (ROOT / ex02.EXERCISE.stub).is_file()
    assert set(ex02.EXERCISE.blocked_modules) == {"mutext.mu", "mutext.uncertain", "mutext.dk"}


def test_cli_list_shows_ex02(capsys):
    assert cli.main(["grade", "--list"]) == 0
    assert EXERCISE in capsys.readouterr().out
