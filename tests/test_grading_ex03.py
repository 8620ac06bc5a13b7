"""Autograder of exercise ex03_free_decay: scores, feedback, integrity (mutext.sysid blocked).

On the inputs of one seed the reference solution and a submission importing mutext.sysid are graded
confined (tests/grading_harness.py: once, in the background); the stub, the submissions
``tests/grading_submissions/ex03_*.py`` and one trivial submission go through the same grader with their
functions run in this process (all of them confined, and the reference on two more seeds, with
``-m slow``); the trivial submissions ``tests/grading_submissions/trivial/ex03_*.py`` are scored
in-process on several seeds; the feedback of each diagnosis is also checked in-process on constructed
answers, and on the inputs of several seeds, that it never contains a reference value.
"""
import math
import re

import numpy as np
import pytest

from grading_harness import ROOT, SUBS, Submissions, assert_same_scores_and_feedback, full, load, q
from mutext import cli
from mutext_grader import ex03_free_decay as ex03
from mutext_grader import grade
from mutext_grader.solutions import ex03_free_decay as sol

EXERCISE = "ex03_free_decay"
SEED = 20250611                  # the inputs of the graded submissions (any seed must do)
MORE_SEEDS = (7, 123456789)      # the reference solution scores full marks on these too
TRIVIAL = {p.stem: p for p in (SUBS / "trivial").glob("ex03_*.py")}
SYSID_CHEAT = ((ROOT / "exercises" / "ex03_free_decay.py").read_text() + "\n\n"
               "def stiffness(omega_bare, m_c):\n"
               "    import mutext.sysid\n"
               "    return omega_bare**2 * m_c\n"
               "\n\n"
               "def cart_mass(omega_bare, omega_weighted, m_w):\n"
               "    return m_w * omega_weighted**2 / (omega_bare**2 - omega_weighted**2)\n")

graded = Submissions(EXERCISE, SEED, extra={"ex03_constants": TRIVIAL["ex03_constants"]})
SUBMISSIONS = graded.paths
CASES = ex03.draw(np.random.default_rng(SEED))       # the inputs the submissions above were graded on
#: graded in this process by default, confined with -m slow
HERE = sorted(n for n in SUBMISSIONS if n != "reference")


# ----------------------------------------------------------------------------
# graded submissions
# ----------------------------------------------------------------------------

def test_reference_solution_scores_full_marks():
    rep = graded("reference")
    assert rep.max_score == 10
    assert [x.max_score for x in rep.questions] == [1.5, 1.5, 1.5, 1.5, 2, 2]
    assert [(x.id, x.name) for x in rep.questions] == [
        ("a1", "(a1) natural_frequency: frequency from peak times, eq. 3.1 (rad/s)"),
        ("a2", "(a2) damping_ratio: damping ratio from the log decrement, eq. 3.2"),
        ("b1", "(b1) cart_mass: cart mass from the added mass, eq. 3.3"),
        ("b2", "(b2) stiffness: equivalent stiffness, eq. 3.4"),
        ("c", "(c) damping_coefficient: damping coefficient, eq. 3.5"),
        ("d", "(d) identify_cart: (m_c, k, c) from a bare and a weighted decay")]
    assert rep.score == 10, rep.text()
    assert rep.inputs == f"drawn from seed {SEED}"


@pytest.mark.parametrize("seed", MORE_SEEDS)
def test_reference_solution_scores_full_marks_on_other_seeds(seed):
    rep = graded.here("reference", seed)
    assert rep.score == 10 and rep.inputs == f"drawn from seed {seed}", rep.text()


@pytest.mark.slow
@pytest.mark.parametrize("seed", MORE_SEEDS)
def test_reference_solution_scores_full_marks_on_other_seeds_confined(seed):
    rep = graded("reference", seed)
    assert rep.score == 10 and rep.inputs == f"drawn from seed {seed}", rep.text()


@pytest.mark.slow
@pytest.mark.parametrize("name", HERE)
def test_confined_run_agrees_with_the_run_in_process(name):
    """What the default run checks on the functions run in this process holds for the confined run."""
    assert_same_scores_and_feedback(graded(name), graded.here(name))


def _scores(qs, mod):
    """Points per question of the functions of ``mod`` called in-process on the inputs of ``qs``."""
    out = {}
    for qid, qu in qs.items():
        outcomes = []
        for c in qu.calls:
            try:
                outcomes.append(_payload(getattr(mod, qu.function)(*c.args, **c.kwargs), qu.kind))
            except Exception as exc:   # noqa: BLE001
                outcomes.append({"ok": False, "error": repr(exc)})
        out[qid] = qu.check(outcomes)[0]
    return out


@pytest.mark.parametrize("name", sorted(TRIVIAL))
def test_trivial_submissions_score_zero(name):
    """Constants (the thesis's cart), zeros, returned arguments and numpy one-liners that are not eqs.
    3.1-3.5 (a plain FFT's largest bin, the first over the last sample) earn nothing, on any draw."""
    mod = load(TRIVIAL[name])
    for seed in (SEED, 1, 2, 3, 4):
        scores = _scores(_questions(seed), mod)
        assert all(v == 0 for v in scores.values()), (seed, scores)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(TRIVIAL))
def test_trivial_submissions_graded_score_zero(name):
    rep = grade(EXERCISE, TRIVIAL[name], 60.0, seed=SEED)
    assert rep.score == 0 and all(x.status == "ok" for x in rep.questions), rep.text()


def test_constants_are_named():
    rep = graded.here("ex03_constants")
    assert rep.score == 0
    for qid in ("a1", "a2", "b1", "b2", "c"):
        assert "every call returned the same value although the inputs differ" in q(rep, qid).output
    assert q(rep, "d").output.count("every call returned the same value") == 3


def test_stub_scores_zero_without_crashing():
    rep = graded.here("stub")
    assert rep.score == 0
    for x in rep.questions:
        assert x.status == "ok"
        assert x.output.count("not implemented yet") == 1


def test_printed_eq_3_3_is_named():
    rep = graded.here("ex03_thesis_eq33")
    assert full(rep, "a1", "a2", "b2", "c")
    b1 = q(rep, "b1")
    assert b1.score == 0 and b1.output.count("this is m_c + m_w") == 3
    assert "m_c = m_w omega_w^2 / (omega_c^2 - omega_w^2)" in b1.output
    d = q(rep, "d")
    assert d.score == 0
    assert "thesis's printed eq. 3.3" in d.output and "follows from a mass m_c + m_w" in d.output
    assert rep.score == 6.5


def test_hz_instead_of_rad_per_s_is_named():
    rep = graded.here("ex03_hz")
    a1 = q(rep, "a1")
    assert a1.score == 0 and a1.output.count("Hz instead of rad/s") == 3
    assert full(rep, "a2", "b1", "b2", "c")
    d = q(rep, "d")
    assert math.isclose(d.score, 0.67)               # the mass is a ratio of frequencies: right in Hz too
    assert "1/(2 pi)^2 times the expected one" in d.output and "1/(2 pi) times" in d.output
    assert rep.score < 10


def test_decrement_not_divided_by_cycles_is_named():
    rep = graded.here("ex03_decrement_not_per_cycle")
    a2 = q(rep, "a2")
    assert a2.score == 0
    for *_, n, _x0, _duration in CASES["a"]:
        assert f"zeta is {n} times too large" in a2.output
    assert full(rep, "a1", "b1", "b2", "c")
    d = q(rep, "d")
    assert math.isclose(d.score, 1.33) and "divided by the number of cycles N" in d.output
    assert rep.score < 10


def test_every_wrong_submission_scores_less():
    for name in SUBMISSIONS:
        if name.startswith("ex03_"):
            assert graded.here(name).score < 10, name


# ----------------------------------------------------------------------------
# diagnoses, in-process
# ----------------------------------------------------------------------------

def _payload(x, kind):
    if kind == "array":
        x = np.asarray(x, dtype=float)
        return {"ok": True, "value": {"shape": list(x.shape), "data": x.ravel().tolist()}}
    return {"ok": True, "value": float(x)}


def _questions(seed):
    return {x.id: x for x in ex03.questions(np.random.default_rng(seed))}


@pytest.fixture(scope="module")
def questions():
    return _questions(SEED)


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


def test_solution_peaks_are_the_library_detector(questions):
    """The solution writes out :func:`mutext.sysid.decay_peaks` (a submission may not import it):
    both find the same peaks on every record of the exercise, noisy ones included."""
    from mutext.sysid import decay_peaks
    records = [c.args[:2] for c in questions["a1"].calls]
    records += [args for c in questions["d"].calls for args in (c.args[0:2], c.args[2:4])]
    assert len(records) == 7
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
    sub.write_text(SYSID_CHEAT)
    rep = grade(EXERCISE, sub, 60.0, seed=SEED)
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


# ----------------------------------------------------------------------------
# inputs drawn per run; no reference in the feedback
# ----------------------------------------------------------------------------

def test_inputs_depend_on_the_seed_only():
    one, again, other = _questions(1), _questions(1), _questions(2)
    for qid in one:
        args = [c.args for c in one[qid].calls]
        assert args == [c.args for c in again[qid].calls], qid             # the same seed: the same inputs
        assert all(a != b for a, b in zip(args, [c.args for c in other[qid].calls])), qid
    assert ex03.draw(np.random.default_rng(1)) == ex03.draw(np.random.default_rng(1))


def test_draws_keep_the_thesis_difficulty():
    """Over many seeds: carts within 30 % of the rig's, damping ratios where eqs. 3.1/3.2 hold, enough
    cycles in every record, references of one question far enough apart for the rule on constants."""
    for seed in range(40):
        cases = ex03.draw(np.random.default_rng(seed))
        for m, k, c, cycles, x0, duration in cases["a"]:
            wn, wd, z = ex03.exact_values(m, k, c)
            assert 0.008 <= z <= 0.1 and 3 <= cycles <= 8 and 2.6 <= duration <= 3.4
            assert (cycles + 1.5) * ex03.TWO_PI / wd <= duration
            frac = duration * wd / ex03.TWO_PI % 1
            assert 0.3 < frac < 0.7                                  # between two FFT bins
        assert ex03._separated([ex03.exact_values(*r[:3])[1] for r in cases["a"]], 1.05)
        assert ex03._separated([ex03.exact_values(*r[:3])[2] for r in cases["a"]], 1.15)
        for m_c, k, c, m_w, x0, durations, seeds in cases["d"]:
            assert 1.38 <= m_w / m_c <= 2.81 and math.sqrt(k / (m_c + m_w)) >= ex03.MIN_OMEGA_W
        for i in range(3):
            assert ex03._separated([x[i] for x in cases["d"]], ex03.SEPARATION)


def _formats(v):
    """How a reference value could appear in a text."""
    v = float(v)
    out = {f"{v:.3g}", f"{v:.4g}", f"{v:.5g}", f"{v:.6g}", f"{v:g}", f"{v:.2f}", f"{v:.3f}", f"{v:.4f}"}
    return {x for x in out if len(x.strip("-0.")) >= 3}


def _leaks(text, values):
    """The reference values found in ``text`` (as whole numbers, not as parts of longer ones)."""
    return sorted(f for v in values for f in _formats(v)
                  if re.search(r"(?<![\d.])" + re.escape(f) + r"(?![\d])", text))


@pytest.mark.parametrize("seed", [SEED, 3, 99])
def test_feedback_never_shows_a_reference(seed):
    """Wrong answers of every kind (a hint's mistake, an arbitrary factor, a constant): neither the
    feedback nor the labels contain a reference value or a cart's parameter."""
    qs = _questions(seed)
    hidden = []
    for c in qs["a1"].calls:
        hidden += [*c.params, *ex03.exact_values(*c.params)]
    for c in qs["d"].calls:
        hidden += list(c.params[:3])
    hidden += [ex03.ref_mass(*c.args) for c in qs["b1"].calls]
    hidden += [c.args[0] ** 2 * c.args[1] for c in qs["b2"].calls]
    hidden += [2 * math.prod(c.args) for c in qs["c"].calls]
    texts = [c.label for qu in qs.values() for c in qu.calls]
    for qid, qu in qs.items():
        right = getattr(sol, qu.function)
        for wrong in (lambda *a: np.asarray(right(*a)) * 1.37, lambda *a: np.asarray(right(*a)) / ex03.TWO_PI,
                      lambda *a: np.asarray(right(*a)) * 2, lambda *a: np.asarray(right(*a)) * 0.6,
                      lambda *a: [1.0, 1.0, 1.0] if qu.kind == "array" else 1.0):
            score, fb = qu.check([_payload(wrong(*c.args), qu.kind) for c in qu.calls])
            assert score == 0, (qid, fb)
            texts += fb
    text = "\n".join(texts)
    assert _leaks(text, hidden) == []
    # the test can fail: the old feedback printed the reference
    assert _leaks(f"expected {hidden[0]:.4g}, got 1", hidden)


def test_an_added_mass_or_a_record_sample_is_no_answer():
    """Returning an argument scores nothing on any draw (the draws keep arguments and answers apart)."""
    for seed in range(12):
        qs = _questions(seed)
        for qid, answer in (("a2", lambda t, y, N: y[0]), ("a1", lambda t, y, N: float(N)),
                            ("b1", lambda wc, ww, mw: mw), ("d", lambda *a: [a[-1]] * 3)):
            score, fb = _check(qs, qid, answer)
            assert score == 0, (seed, qid, fb)


def test_factor_2_hint_only_near_2():
    assert any("a factor 2" in h for h in ex03._ratio_hints(0.5, "c"))
    assert any("a factor 2" in h for h in ex03._ratio_hints(2.004, "c"))
    assert ex03._ratio_hints(0.5182, "c") == []
    assert ex03._ratio_hints(0.5122, "c", tol=1e-4) == []
    assert ex03._ratio_hints(float("nan"), "c") == []
