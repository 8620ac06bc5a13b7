"""ex01 with inputs drawn per run: full marks on several seeds, different inputs for different seeds,
nothing for answers that do not solve the questions, no reference value in the feedback.

Most checks run in this process on the questions of a seed (the submissions are the repository's
own); one trivial submission goes through the grader with its functions run in this process
(tests/grading_harness.py); the confined runs are slow (ex01 is graded confined in
tests/test_grading.py).
"""

import control as ct
import numpy as np
import pytest

import grading_harness as harness
from grading_harness import ROOT, SUBS, load, q
from mutext_grader import ex01_two_mass_hinf as ex01
from mutext_grader.solutions import ex01_two_mass_hinf as sol

EXERCISE = "ex01_two_mass_hinf"
REFERENCE = ROOT / "instructor" / "mutext_grader" / "solutions" / f"{EXERCISE}.py"
TRIVIAL = SUBS / "trivial"
SEEDS = (11, 12, 13)


# ----------------------------------------------------------------------------
# running a submission's functions in this process (also used by the ex02 tests)
# ----------------------------------------------------------------------------

def encode(kind, value):
    """The plain value the child would send back for ``kind``."""
    if kind == "ss":
        if isinstance(value, (tuple, list)):
            value = ct.ss(*value)
        return {**{k: np.asarray(getattr(value, k), float).tolist() for k in "ABCD"}, "dt": 0}
    if kind == "float":
        return float(value)
    a = np.asarray(value, float)
    return {"shape": list(a.shape), "data": a.ravel().tolist()}


def _arg(a):
    return ct.ss(*a["__ss__"]) if isinstance(a, dict) and "__ss__" in a else a


def outcomes(module, question):
    out = []
    for c in question.calls:
        try:
            v = getattr(module, question.function)(*[_arg(a) for a in c.args], **c.kwargs)
            out.append({"ok": True, "value": encode(question.kind, v)})
        except Exception as exc:   # noqa: BLE001
            out.append({"ok": False, "error": f"{type(exc).__name__}: {exc}"})
    return out


def scores(module, questions, only=None):
    """``{qid: (score, feedback)}`` of ``module`` on ``questions`` (the ids in ``only``, or all)."""
    return {x.id: x.check(outcomes(module, x)) for x in questions if only is None or x.id in only}


def number_forms(x):
    """Ways a reference number could be printed (4 or more significant digits)."""
    x = float(x)
    return {f"{x:.4g}", f"{x:.5g}", f"{x:.6g}", f"{x:g}", repr(x), f"{x:.4f}"}


def leaks(lines, numbers):
    """The reference numbers that some feedback line prints."""
    text = "\n".join(lines)
    return sorted({form for x in numbers if np.isfinite(x) and abs(x) > 1e-12 for form in number_forms(x)
                   if form in text})


def _questions(seed):
    return ex01.questions(np.random.default_rng(seed))


# ----------------------------------------------------------------------------
# graded in the background: one trivial submission by default, the reference on three seeds when slow
# ----------------------------------------------------------------------------

def graded(path, seed):
    """The report of ``path`` graded confined on the inputs of ``seed`` (tests/grading_harness.py: once)."""
    return harness.graded(EXERCISE, path, seed)


# ----------------------------------------------------------------------------
# draws
# ----------------------------------------------------------------------------

def _inputs(questions):
    return {x.id: [(c.args, c.kwargs) for c in x.calls] for x in questions}


def test_two_seeds_draw_different_inputs_and_one_seed_the_same():
    one, two = _inputs(_questions(1)), _inputs(_questions(2))
    for qid in ("a", "c"):
        for c1, c2 in zip(one[qid], two[qid]):
            assert c1 != c2, qid
    assert one["b"][0] == two["b"][0] == ([], {})            # the defaults call
    assert one["b"][1:] != two["b"][1:]
    assert _inputs(_questions(1)) == one                     # a seed repeats its inputs
    assert one["d"] == two["d"] == [([], {})]                # controller() has no inputs


def test_drawn_parameters_stay_near_the_fixed_cases_and_away_from_the_defaults():
    for seed in range(20):
        d = ex01._draw(np.random.default_rng(seed))
        for p, base in zip(d["mech"], (ex01.DEFAULTS, ex01.OTHER)):
            assert all(0.69 * base[k] <= p[k] <= 1.31 * base[k] for k in ex01.MECH)
        full_args = d["plant"][2]
        for k in ex01.WEIGHTS:      # a weight hard-coded to its default is seen
            assert abs(full_args[k] / ex01.DEFAULTS[k] - 1) >= 0.099
        assert [lab for lab, _ in d["systems"]][1].startswith("lightly damped resonance")


def test_prepare_computes_the_references_of_the_same_draws():
    ex01._norm_cached.cache_clear()
    ex01.prepare(np.random.default_rng(7))
    info = ex01._norm_cached.cache_info()
    for _, s in ex01._draw(np.random.default_rng(7))["systems"]:
        ex01._ref_norm(s)
    after = ex01._norm_cached.cache_info()
    assert after.misses == info.misses and after.hits == info.hits + 5


# ----------------------------------------------------------------------------
# full marks, nothing for non-answers
# ----------------------------------------------------------------------------

@pytest.mark.parametrize("seed", SEEDS)
def test_reference_scores_full_marks_in_process(seed):
    res = scores(sol, _questions(seed))
    for qid, (score, fb) in res.items():
        assert score == ex01.POINTS[qid], (seed, qid, fb)
        assert fb[0].startswith("correct") or qid == "d"


@pytest.mark.parametrize("name", ["ex01_shortcuts", "ex01_padded", "ex01_ill_conditioned"])
def test_trivial_submissions_earn_nothing_in_process(name):
    mod = load(TRIVIAL / f"{name}.py")
    for seed in SEEDS[:2]:
        res = scores(mod, _questions(seed))
        assert {qid: s for qid, (s, _) in res.items()} == {qid: 0 for qid in res}, (seed, res)


@pytest.mark.slow
def test_ex01_padded_confined_agrees_with_the_run_in_process():
    """The default run grades ``ex01_padded.py`` with its functions run in this process; confined, the same."""
    path = TRIVIAL / "ex01_padded.py"
    harness.assert_same_scores_and_feedback(graded(path, SEEDS[0]), harness.graded_here(EXERCISE, path, SEEDS[0]))


def test_padded_submission_graded_scores_zero_and_nothing_is_computed():
    rep = harness.graded_here(EXERCISE, TRIVIAL / "ex01_padded.py", SEEDS[0])
    assert rep.score == 0, rep.text()
    for qid in ("a", "b", "d"):
        assert "at most 12 are accepted" in q(rep, qid).output and "not evaluated" in q(rep, qid).output
    assert rep.seconds < 120


def _controller(K):
    return ex01._check_controller([{"ok": True, "value": encode("ss", K)}], [ex01.Call("controller()")])


def _pad(K, A_extra, b=None, c=None):
    A, B, C, D = (np.asarray(X, float) for X in (K.A, K.B, K.C, K.D))
    n, m = A.shape[0], A_extra.shape[0]
    Ap = np.block([[A, np.zeros((n, m))], [np.zeros((m, n)), A_extra]])
    Bp = np.vstack([B, np.zeros((m, 1)) if b is None else b])
    Cp = np.hstack([C, np.zeros((1, m)) if c is None else c])
    return ct.ss(Ap, Bp, Cp, D)


def test_controllers_that_do_not_solve_earn_nothing():
    K = sol.controller()
    assert _controller(K)[0] == 3
    # stable modes nothing reaches, within the size limit: the same closed loop, the same marks
    assert _controller(_pad(K, -np.diag([1.0, 2.0, 5.0, 10.0])))[0] == 3
    # an unstable mode nothing sees is still inside the loop: unstable
    score, fb = _controller(_pad(K, np.array([[0.5]]), b=np.ones((1, 1))))
    assert score == 0 and "unstable" in fb[0]
    # an undamped mode of the controller nothing reaches: not stable
    assert _controller(_pad(K, np.array([[0.0, 3.0], [-3.0, 0.0]])))[0] == 0
    # zero, static, the plant's own channel u -> x2 as the controller
    assert _controller(ct.ss([], [], [], [[0.0]]))[0] == 0
    assert _controller(ct.ss([], [], [], [[-500.0]]))[0] == 0
    G = sol.mechanical_model(1.0, 2.0, 450.0, 175.0)
    assert _controller(ct.ss(G.A, np.asarray(G.B)[:, [1]], np.asarray(G.C)[[1]], [[0.0]]))[0] == 0
    # the right controller padded past the size limit: not computed
    score, fb = _controller(_pad(K, -np.eye(9)))
    assert score == 0 and "13 states; at most 12" in fb[0]
    score, fb = _controller(_pad(ct.ss([], [], [], [[0.0]]), -np.eye(400)))
    assert score == 0 and "400 states; at most 12" in fb[0] and "not evaluated" in fb[0]


def test_a_plant_with_only_its_zero_channels_right_earns_nothing():
    qb = next(x for x in _questions(3) if x.id == "b")
    zero = ct.ss([], [], [], np.zeros((3, 3)))
    score, fb = qb.check([{"ok": True, "value": encode("ss", zero)}] * len(qb.calls))
    assert score == 0 and any("earn nothing by themselves" in line for line in fb)


# ----------------------------------------------------------------------------
# feedback without reference values
# ----------------------------------------------------------------------------

def test_the_leak_check_sees_a_printed_reference():
    assert leaks(["[system 2] expected 251.3, got 77.3"], [251.3127]) == ["251.3"]
    assert not leaks(["your value 77.3 is too low"], [251.3127])


def test_feedback_on_wrong_answers_prints_no_reference_number():
    qs = {x.id: x for x in _questions(SEEDS[1])}
    draw = ex01._draw(np.random.default_rng(SEEDS[1]))

    class Wrong:
        @staticmethod
        def mechanical_model(m1, m2, k1, k2):
            return sol.mechanical_model(1.3 * m1, m2, k1, 0.8 * k2)

        @staticmethod
        def generalized_plant(**kw):
            p = {**ex01.DEFAULTS, **kw}
            p["x_max"] *= 1.7
            p["eta_max"] = 1e-4
            return sol.generalized_plant(**p)

        @staticmethod
        def hinf_norm(s):
            return 1.37 * sol.hinf_norm(s) if s.nstates % 2 else 0.999 * sol.hinf_norm(s)

    res = scores(Wrong, qs.values(), only=("a", "b", "c"))
    assert all(s < ex01.POINTS[qid] for qid, (s, _) in res.items())
    numbers = [v for p in draw["mech"] + draw["plant"] for v in p.values()]
    numbers += [ex01._ref_norm(s) for _, s in draw["systems"]]
    for p in draw["mech"]:
        G = sol.mechanical_model(**p)
        numbers += list(np.abs(ct.evalfr(G, 0.0)).ravel())                           # static gains
        numbers += list(np.sqrt(np.abs(np.linalg.eigvals(np.asarray(G.A)))))      # natural frequencies
    fb = [line for _, lines in res.values() for line in lines]
    assert not leaks(fb, numbers), (leaks(fb, numbers), fb)
    assert any("too high" in line for line in res["c"][1]) and any("too low" in line for line in res["c"][1])
    assert all(x.label.startswith("parameter set") for x in qs["a"].calls)


# ----------------------------------------------------------------------------
# the confined child on three seeds (slow)
# ----------------------------------------------------------------------------

@pytest.mark.slow
@pytest.mark.parametrize("seed", SEEDS)
def test_reference_scores_full_marks_graded(seed):
    rep = graded(REFERENCE, seed)
    assert rep.score == 10, rep.text()
    assert f"seed {seed}" in rep.inputs


@pytest.mark.slow
@pytest.mark.parametrize("name", ["ex01_shortcuts", "ex01_ill_conditioned"])
def test_trivial_submissions_graded_score_zero(name):
    rep = graded(TRIVIAL / f"{name}.py", SEEDS[2])
    assert rep.score == 0, rep.text()
