"""Autograder of exercise ex04_beam_element: scores, feedback, integrity (mutext.rotor blocked).

On the inputs of one seed the reference solution and the submission that imports and reads mutext.rotor
are graded confined (tests/grading_harness.py: once, in the background); the stub, the submissions
``tests/grading_submissions/ex04_*.py`` and one trivial submission with oversized arrays go through
the same grader with their functions run in this process (all of them confined, and the reference on
two more seeds, with ``-m slow``; the size caps on what the child returns are checked confined in
tests/test_grading_resources.py); the trivial submissions
``tests/grading_submissions/trivial/ex04_*.py`` are scored in-process on several seeds (graded one by
one with ``-m slow``); the feedback of each diagnosis is also checked in-process on constructed
answers, and that it never contains a reference value.
"""
import math
import re

import numpy as np
import pytest

from grading_harness import ROOT, SUBS, Submissions, assert_same_scores_and_feedback, full, load, q
from mutext import cli
from mutext_grader import ex04_beam_element as ex04
from mutext_grader import grade
from mutext_grader.solutions import ex04_beam_element as sol

EXERCISE = "ex04_beam_element"
SEED = 20250611                  # the inputs of the graded submissions (any seed must do)
MORE_SEEDS = (7, 123456789)      # the reference solution scores full marks on these too
TRIVIAL = {p.stem: p for p in (SUBS / "trivial").glob("ex04_*.py")}

graded = Submissions(EXERCISE, SEED, extra={"ex04_oversized": TRIVIAL["ex04_oversized"]},
                     confined=("reference", "ex04_cheat_rotor"))
SUBMISSIONS = graded.paths
CASES = ex04.draw(np.random.default_rng(SEED))       # the inputs the submissions above were graded on
#: graded in this process by default, confined with -m slow
HERE = sorted(n for n in SUBMISSIONS if n not in graded.confined)


# ----------------------------------------------------------------------------
# graded submissions
# ----------------------------------------------------------------------------

def test_reference_solution_scores_full_marks():
    rep = graded("reference")
    assert rep.max_score == 10 and [x.max_score for x in rep.questions] == [3, 2, 2, 3]
    assert [(x.id, x.name) for x in rep.questions] == [
        ("a", "(a) element_matrices: element stiffness and consistent mass matrices"),
        ("b", "(b) assemble: global matrices with supports"),
        ("c", "(c) natural_frequencies: natural frequencies in rad/s"),
        ("d", "(d) relative_errors: convergence against the exact frequency")]
    assert rep.score == 10, rep.text()
    assert rep.inputs == f"drawn from seed {SEED}"
    assert "h^4 convergence" in q(rep, "d").output


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


def test_oversized_arrays_score_zero_unanalysed():
    rep = graded.here("ex04_oversized")
    assert rep.score == 0 and all(x.status == "ok" for x in rep.questions)
    assert "must return the pair (K, M) of 4x4 arrays" in q(rep, "a").output
    for n, *_ in CASES["b"]:
        assert f"the matrices are 120x120, far larger than the {2 * n}x{2 * n} asked" in q(rep, "b").output
    assert "got 5000 numbers" in q(rep, "c").output and "got 2000 numbers" in q(rep, "d").output


def test_stub_scores_zero_without_crashing():
    rep = graded.here("stub")
    assert rep.score == 0
    for x in rep.questions:
        assert x.status == "ok"
        assert x.output.count("not implemented yet") == 1


def test_lumped_mass_is_named():
    rep = graded.here("ex04_lumped_mass")
    a = q(rep, "a")
    assert a.score == 1.5                    # K right, M wrong at both parameter sets
    assert "mass matrix is lumped, not consistent" in a.output
    assert q(rep, "b").score == 1.0 and "M differs" in q(rep, "b").output
    assert q(rep, "c").score == 0 and q(rep, "d").score == 0
    assert "errors are negative" in q(rep, "d").output and "lumped mass matrix" in q(rep, "d").output
    assert rep.score < 10


def test_missing_factor_L_is_named():
    rep = graded.here("ex04_missing_L")
    a = q(rep, "a")
    assert a.score == 1.5
    assert "a factor L is missing in the rotational terms of the stiffness matrix K" in a.output
    assert "mass matrix" not in a.output     # M is right
    assert q(rep, "b").score == 1.0 and "K differs" in q(rep, "b").output
    assert rep.score == 2.5


def test_supports_not_applied_is_named():
    rep = graded.here("ex04_no_supports")
    assert full(rep, "a")
    b = q(rep, "b")
    assert b.score == 1.0                    # right free-beam matrices: half the points
    for n, _length, _mat, support in CASES["b"]:
        size = 2 * (n + 1)
        assert f"boundary conditions not applied: the matrices are {size}x{size}" in b.output
        if support == "pinned":
            assert f"(w1, w{n + 1} for a pinned-pinned beam), leaving {2 * n}x{2 * n}" in b.output
        else:
            assert f"(w1, theta1 for a cantilever beam), leaving {2 * n}x{2 * n}" in b.output
    c = q(rep, "c")
    assert c.score == 0
    assert "boundary conditions not applied: you have rigid-body zero frequencies" in c.output
    assert "rigid-body mode" in q(rep, "d").output and q(rep, "d").score == 0
    assert rep.score == 4


def test_hz_and_pinned_beta_for_cantilever_are_named():
    rep = graded.here("ex04_hz_and_pi")
    assert full(rep, "a", "b")
    assert q(rep, "c").score == 0 and "these are in Hz: return rad/s" in q(rep, "c").output
    d = q(rep, "d")
    assert d.score == 1                      # the pinned-pinned call is right
    assert "beta L = pi, which is the pinned-pinned value" in d.output
    from mutext.rotor.analytic import beta_l
    for _, _, support, mode, *_ in CASES["d"]:
        if support == "cantilever":
            assert f"beta_{mode} L = {beta_l('cantilever', mode):.10f}" in d.output
    assert rep.score == 6


def test_importing_or_reading_mutext_rotor_is_blocked():
    rep = graded("ex04_cheat_rotor")
    a, c = q(rep, "a"), q(rep, "c")
    assert a.score == 0 and a.status == "violation" and "importing mutext.rotor" in a.output
    assert c.score == 0 and c.status == "violation" and "rotor/elements.py" in c.output
    assert full(rep, "b")
    assert rep.score == 2


def test_every_wrong_submission_scores_less():
    for name in SUBMISSIONS:
        if name.startswith("ex04_"):
            assert (graded(name) if name in graded.confined else graded.here(name)).score < 10, name


# ----------------------------------------------------------------------------
# diagnoses, in-process
# ----------------------------------------------------------------------------

def _payload(x):
    x = np.asarray(x, dtype=float)
    return {"ok": True, "value": {"shape": list(x.shape), "data": x.ravel().tolist()}}


def _questions(seed=SEED):
    return {x.id: x for x in ex04.questions(np.random.default_rng(seed))}


_QUESTIONS = _questions()


def _question(qid):
    return _QUESTIONS[qid]


def _check(qid, answer):
    """Grade ``answer(*args, **kwargs)`` for every call of question ``qid`` in-process."""
    qu = _question(qid)
    return qu.check([_payload(answer(*c.args, **c.kwargs)) for c in qu.calls])


def test_reference_solution_agrees_with_mutext_rotor():
    """The numpy solution equals the Timoshenko element of mutext.rotor with shear and rotary inertia off."""
    from mutext.rotor.elements import section_properties, timoshenko_plane_matrices
    E, rho, d, L = 2.1e11, 7800.0, 0.02, 0.3
    A, I = section_properties(d, 0.0)
    Mt, Mr, K = timoshenko_plane_matrices(E, E / 2.6, rho, L, d, 0.0, 1.0, shear=False)
    Ks, Ms = sol.element_matrices(E, I, rho, A, L)
    np.testing.assert_allclose(Ks, np.asarray(K.full()), rtol=1e-13, atol=1e-6)
    np.testing.assert_allclose(Ms, np.asarray(Mt.full()), rtol=1e-13, atol=1e-15)
    for support, n in (("pinned", 3), ("cantilever", 4)):
        Kr, Mref = ex04.supported(n, 1.2, E, d, rho, support)
        Ks, Ms = sol.assemble(n, 1.2, E, I, rho, A, support)
        np.testing.assert_allclose(Ks, Kr, rtol=1e-12, atol=1e-9 * np.abs(Kr).max())
        np.testing.assert_allclose(Ms, Mref, rtol=1e-12, atol=1e-12 * np.abs(Mref).max())
    # the analytic roots: cos x cosh x = -1 for the cantilever
    for x in sol.BETA_L["cantilever"]:
        assert abs(math.cos(x) * math.cosh(x) + 1) < 1e-9 * math.cosh(x)
    # h^4 convergence, errors positive (consistent mass: upper bound)
    e = sol.relative_errors(1.2, E, I, rho, A, "pinned", 1)
    assert np.all(e > 0) and np.all(e[:-1] / e[1:] > 14)


def test_full_marks_in_process():
    for qid, fn in (("a", sol.element_matrices), ("b", sol.assemble), ("c", sol.natural_frequencies),
                    ("d", sol.relative_errors)):
        score, fb = _check(qid, fn)
        assert score == ex04.POINTS[qid], fb
        assert fb[0].startswith("correct")


@pytest.mark.parametrize("transform, text", [
    (lambda K, M, L: (K[np.ix_([0, 2, 1, 3], [0, 2, 1, 3])], M), "order [w1, w2, theta1, theta2]"),
    (lambda K, M, L: (ex04.SIGN @ K @ ex04.SIGN, M), "theta is dw/dz"),
    (lambda K, M, L: (K * L, M), "K is L times the expected one: check the power of L in the prefactor EI/L^3 "
                                 "(e.g. EI/L^2 instead of EI/L^3)"),
    (lambda K, M, L: (K, M / 2), "M is 0.5 times the expected one: check the prefactor rho A L/420"),
    (lambda K, M, L: (M, K), "K and M are swapped"),
])
def test_element_diagnoses(transform, text):
    score, fb = _check("a", lambda *a: transform(*sol.element_matrices(*a), a[-1]))
    assert score < ex04.POINTS["a"]
    assert any(text in line for line in fb), fb


def test_rotary_inertia_and_missing_L_in_mass():
    def rayleigh(E, I, rho, A, L):
        K, M = sol.element_matrices(E, I, rho, A, L)
        d = math.sqrt(4 * A / math.pi)
        return K, M + ex04.element_reference(E, d, rho, L)[2]

    score, fb = _check("a", rayleigh)
    assert score == 1.5 and any("includes the rotary inertia" in line for line in fb)

    def no_L(E, I, rho, A, L):
        K, _ = sol.element_matrices(E, I, rho, A, L)
        return K, rho * A * L / 420 * np.array([[156, 22, 54, -13], [22, 4, 13, -3], [54, 13, 156, -22],
                                                [-13, -3, -22, 4]])

    score, fb = _check("a", no_L)
    assert score == 1.5 and any("a factor L^2 is missing in the rotational terms of the mass matrix" in line
                                or "a factor L is missing in the rotational terms of the mass matrix" in line
                                for line in fb), fb


def test_assembly_diagnoses():
    def unconnected(n, length, E, I, rho, A, support):
        Ke, Me = sol.element_matrices(E, I, rho, A, length / n)
        return np.kron(np.eye(n), Ke), np.kron(np.eye(n), Me)

    score, fb = _check("b", unconnected)
    assert score == 0 and any("elements look unconnected" in line for line in fb)

    def wrong_support(n, length, E, I, rho, A, support):
        return sol.assemble(n, length, E, I, rho, A, "pinned")      # same size, wrong beam for the cantilever

    score, fb = _check("b", wrong_support)
    assert score == 1 and any("matrices of a pinned-pinned beam" in line for line in fb)

    def clamped_right(n, length, E, I, rho, A, support):
        if support == "pinned":
            return sol.assemble(n, length, E, I, rho, A, support)
        Ke, Me = sol.element_matrices(E, I, rho, A, length / n)
        K, M = np.zeros((2 * n + 2, 2 * n + 2)), np.zeros((2 * n + 2, 2 * n + 2))
        for e in range(n):
            K[2 * e:2 * e + 4, 2 * e:2 * e + 4] += Ke
            M[2 * e:2 * e + 4, 2 * e:2 * e + 4] += Me
        return K[:-2, :-2], M[:-2, :-2]

    score, fb = _check("b", clamped_right)
    assert score == 1 and any("clamped at z = length" in line for line in fb)

    def whole_length(n, length, E, I, rho, A, support):
        return sol.assemble(n, length * n, E, I, rho, A, support)

    score, fb = _check("b", whole_length)
    assert score == 0 and any("an element is length/n_elements long" in line for line in fb)

    def reordered(n, length, E, I, rho, A, support):
        K, M = sol.assemble(n, length, E, I, rho, A, support)
        p = np.r_[np.arange(0, K.shape[0], 2), np.arange(1, K.shape[0], 2)]
        return K[np.ix_(p, p)], M[np.ix_(p, p)]

    score, fb = _check("b", reordered)
    assert score == 1 and any("DOFs are in another order" in line for line in fb)


def test_frequency_diagnoses():
    score, fb = _check("c", lambda *a: sol.natural_frequencies(*a) ** 2)
    assert score == 0 and any("these are omega^2" in line for line in fb)
    score, fb = _check("c", lambda *a: sol.natural_frequencies(*a)[::-1])
    assert score == 0 and any("not in ascending order" in line for line in fb)

    def other_support(n, length, E, I, rho, A, support, n_modes):
        return sol.natural_frequencies(n, length, E, I, rho, A,
                                       "cantilever" if support == "pinned" else "pinned", n_modes)

    score, fb = _check("c", other_support)
    assert score == 0 and any("frequencies of a cantilever beam" in line for line in fb)


@pytest.mark.parametrize("transform, text", [
    (lambda e: 100 * e, "these are percentages"),
    (lambda e: -e / (1 + e), "wrong reference"),
    (lambda e: e * 0.0, "nearly) zero"),
])
def test_error_diagnoses(transform, text):
    score, fb = _check("d", lambda *a, **k: transform(sol.relative_errors(*a, **k)))
    assert score == 0
    assert all(text in line for line in fb), fb


def test_inaccurate_or_wrong_mode_analytic_value():
    def rounded(length, E, I, rho, A, support, mode=1, element_counts=(2, 4, 8)):
        w = [sol.natural_frequencies(n, length, E, I, rho, A, support, mode)[mode - 1] for n in element_counts]
        bl = round(sol.BETA_L[support][mode - 1], 3)
        return np.array(w) / (bl**2 * math.sqrt(E * I / (rho * A * length**4))) - 1

    score, fb = _check("d", rounded)
    assert score < ex04.POINTS["d"] and any("ppm off: use beta L to at least 10 digits" in line for line in fb), fb

    def next_mode(length, E, I, rho, A, support, mode=1, element_counts=(2, 4, 8)):
        w = [sol.natural_frequencies(n, length, E, I, rho, A, support, mode)[mode - 1] for n in element_counts]
        return np.array(w) / sol.analytic_frequency(length, E, I, rho, A, support, mode + 1) - 1

    score, fb = _check("d", next_mode)
    assert score == 0 and all("the analytic value is that of mode" in line for line in fb), fb


def test_bad_payloads_are_reported():
    qu = _question("a")
    score, fb = qu.check([_payload(np.eye(4)), {"ok": False, "error": "boom"}])
    assert score == 0
    assert any("must return the pair (K, M)" in line for line in fb) and any("boom" in line for line in fb)


# ----------------------------------------------------------------------------
# inputs drawn per run; trivial answers; no reference in the feedback
# ----------------------------------------------------------------------------

def test_inputs_depend_on_the_seed_only():
    one, again, other = _questions(1), _questions(1), _questions(2)
    for qid in one:
        args = [(c.args, c.kwargs) for c in one[qid].calls]
        assert args == [(c.args, c.kwargs) for c in again[qid].calls], qid
        assert all(a != b for a, b in zip(args, [(c.args, c.kwargs) for c in other[qid].calls])), qid
    assert ex04.draw(np.random.default_rng(1)) == ex04.draw(np.random.default_rng(1))


def test_prepare_builds_the_references_of_the_same_draw(monkeypatch):
    """prepare(rng) gets a generator seeded as questions' one: it builds exactly the models the checks use."""
    built = []
    monkeypatch.setattr(ex04, "_free_free_cached", lambda *a: built.append(a) or (np.eye(2), np.eye(2)))
    ex04.prepare(np.random.default_rng(5))
    cases = ex04.draw(np.random.default_rng(5))
    want = {(n, length, mat["E"], mat["d"], mat["rho"]) for n, length, mat, *_ in cases["b"] + cases["c"]}
    want |= {(n, length, mat["E"], mat["d"], mat["rho"]) for length, mat, _, _, counts in cases["d"] for n in counts}
    assert set(built) == want


def test_draws_vary_what_matters():
    """Over many seeds: element lengths far from 1 m (a wrong power of L shows), one beam of each support in
    (b) and (c), the modes of (d) as listed, several materials and element counts."""
    seen = {"E": set(), "n": set(), "modes": set()}
    for seed in range(40):
        cases = ex04.draw(np.random.default_rng(seed))
        assert sorted(L > 1 for _, L in cases["a"]) == [False, True]
        assert all(abs(math.log(L)) > 0.4 for _, L in cases["a"])
        for key in ("b", "c"):
            assert sorted(x[3] for x in cases[key]) == ["cantilever", "pinned"]
        assert sorted(x[2] for x in cases["d"]) == ["cantilever", "cantilever", "pinned"]
        seen["E"] |= {round(m["E"], -10) for m, _ in cases["a"]}
        seen["n"] |= {x[0] for x in cases["b"] + cases["c"]}
        seen["modes"] |= {(x[2], x[3]) for x in cases["d"]}
        for x in cases["d"]:
            counts = x[4]
            assert len(counts) == 3 and list(counts) == sorted(set(counts)) and 2 <= counts[0] and counts[-1] <= 8
            seen.setdefault("counts", set()).add(tuple(counts))
    assert len(seen["counts"]) >= 5          # no fixed table of (d)'s errors to copy
    assert len(seen["E"]) >= 4 and seen["n"] == {3, 4, 5, 6}
    assert seen["modes"] == {("pinned", 1), ("pinned", 2), ("cantilever", 1), ("cantilever", 2), ("cantilever", 3)}


@pytest.mark.parametrize("name", sorted(set(TRIVIAL) - {"ex04_oversized"}))
def test_trivial_submissions_score_zero(name):
    """Zeros, identity matrices scaled by the arguments, constants, and the closed-form frequencies in place
    of the finite-element ones earn nothing, on any draw."""
    mod = load(TRIVIAL[name])
    for seed in (SEED, 1, 2):
        for qid, qu in _questions(seed).items():
            outcomes = []
            for c in qu.calls:
                try:
                    outcomes.append(_payload(getattr(mod, qu.function)(*c.args, **c.kwargs)))
                except NotImplementedError as exc:
                    outcomes.append({"ok": False, "error": repr(exc)})
            score, fb = qu.check(outcomes)
            assert score == 0, (seed, qid, fb)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(TRIVIAL))
def test_trivial_submissions_graded_score_zero(name):
    rep = grade(EXERCISE, TRIVIAL[name], 60.0, seed=SEED)
    assert rep.score == 0 and all(x.status == "ok" for x in rep.questions), rep.text()


def test_oversized_arrays_are_never_factorised(monkeypatch):
    """Sizes are checked before any computation: far larger arrays score 0 and reach no eigensolver."""
    def refuse(*a, **k):
        raise AssertionError("an eigensolver was called")

    monkeypatch.setattr(ex04, "frequencies", refuse)
    monkeypatch.setattr(ex04.sla, "eigh", refuse)
    monkeypatch.setattr(ex04.sla, "eigvals", refuse)
    big = np.eye(300)
    for qid, value in (("a", np.stack([np.eye(60)] * 2)), ("b", np.stack([big, big])), ("c", np.ones(30000)),
                       ("d", np.ones(30000))):
        qu = _question(qid)
        score, fb = qu.check([_payload(value) for _ in qu.calls])
        assert score == 0 and len(fb) == len(qu.calls), fb
        text = {"a": "must return the pair (K, M) of 4x4 arrays", "b": "300x300, far larger than the",
                "c": "got 30000 numbers", "d": "got 30000 numbers"}[qid]
        assert all(text in line for line in fb), fb


def _formats(v):
    v = float(v)
    out = {f"{v:.3g}", f"{v:.4g}", f"{v:.5g}", f"{v:.6g}", f"{v:g}"}
    return {x for x in out if len(x.strip("-0.")) >= 3}


def _leaks(text, values):
    return sorted(f for v in values for f in _formats(v)
                  if re.search(r"(?<![\d.])" + re.escape(f) + r"(?![\d])", text))


def _references(qs):
    """Every reference value of the calls: matrix entries, frequencies, errors, exact frequencies."""
    vals = []
    for c in qs["a"].calls:
        E, I, rho, A, L = c.args
        vals += [x for X in ex04.element_reference(E, c.kwargs_ref["d"], rho, L)[:2] for x in X.ravel() if x]
    for c in qs["b"].calls:
        n, length, E, I, rho, A, support = c.args
        vals += [x for X in ex04.supported(n, length, E, c.kwargs_ref["d"], rho, support) for x in X.ravel() if x]
    for c in qs["c"].calls:
        n, length, E, I, rho, A, support, k = c.args
        vals += list(ex04.frequencies(*ex04.supported(n, length, E, c.kwargs_ref["d"], rho, support), k))
    for c in qs["d"].calls:
        length, E, I, rho, A, support = c.args
        d, mode = c.kwargs_ref["d"], c.kwargs["mode"]
        vals += list(ex04.reference_errors(length, E, d, rho, support, mode))
        vals.append(ex04.exact_frequency(length, E, d, rho, support, mode))
    return vals


def test_feedback_never_shows_a_reference():
    """Wrong answers of many kinds (hinted mistakes, arbitrary factors, another support, noise): the feedback
    holds none of the reference values."""
    rng = np.random.default_rng(0)
    wrong = {
        "a": [lambda *a: np.array(sol.element_matrices(*a)) * 1.37,
              lambda *a: np.array(sol.element_matrices(*a)) * (1 + 0.01 * rng.standard_normal((2, 4, 4))),
              lambda *a: (sol.element_matrices(*a)[0][np.ix_([0, 2, 1, 3], [0, 2, 1, 3])],
                          sol.element_matrices(*a)[1] * 0.77)],
        "b": [lambda *a: np.array(sol.assemble(*a)) * 1.37,
              lambda *a: np.array(sol.assemble(*a)) * (1 + 0.01 * rng.standard_normal(np.shape(sol.assemble(*a))))],
        "c": [lambda *a: sol.natural_frequencies(*a) * 1.37, lambda *a: sol.natural_frequencies(*a) / (2 * np.pi),
              lambda *a: sol.natural_frequencies(*a) * (1 + 0.01 * rng.standard_normal(a[-1]))],
        "d": [lambda *a, **k: sol.relative_errors(*a, **k) * 1.37,
              lambda *a, **k: sol.relative_errors(*a, **k) + 1e-3,
              lambda *a, **k: (1 + sol.relative_errors(*a, **k)) * 1.0123 - 1],
    }
    for seed in (SEED, 3):
        qs = _questions(seed)
        texts = [c.label for qu in qs.values() for c in qu.calls]
        for qid, answers in wrong.items():
            for answer in answers:
                score, fb = qs[qid].check([_payload(answer(*c.args, **c.kwargs)) for c in qs[qid].calls])
                assert score < ex04.POINTS[qid], (qid, fb)
                texts += fb
        refs = _references(qs)
        text = "\n".join(texts)
        assert _leaks(text, refs) == [], _leaks(text, refs)
        assert _leaks(f"expected {refs[-1]:.6g}", refs)           # the check can fail


def test_listed_and_stub_named():
    assert ex04.EXERCISE.stub == "exercises/ex04_beam_element.py"
    assert (ROOT / ex04.EXERCISE.stub).is_file()
    assert "mutext.rotor" in ex04.EXERCISE.blocked_modules


def test_cli_list_shows_ex04(capsys):
    assert cli.main(["grade", "--list"]) == 0
    out = capsys.readouterr().out
    assert EXERCISE in out and "ex01_two_mass_hinf" in out
