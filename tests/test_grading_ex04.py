"""Autograder of exercise ex04_beam_element: scores, feedback, integrity (mutext.rotor blocked).

The submissions ``tests/grading_submissions/ex04_*.py``, the reference
solution and the stub are graded once, two at a time in the background; the
feedback of each diagnosis is also checked in-process on constructed answers.
"""
import math

import numpy as np
import pytest

from grading_harness import ROOT, GradedSubmissions, full, q
from mutext import cli
from mutext_grader import ex04_beam_element as ex04
from mutext_grader.solutions import ex04_beam_element as sol

EXERCISE = "ex04_beam_element"
graded = GradedSubmissions(EXERCISE)
SUBMISSIONS = graded.paths


# ----------------------------------------------------------------------------
# graded submissions
# ----------------------------------------------------------------------------

def test_reference_solution_scores_full_marks():
    rep = graded("reference")
    assert rep.max_score == 10 and [x.max_score for x in rep.questions] == [3, 2, 2, 3]
    assert rep.score == 10, rep.text()
    assert "h^4 convergence" in q(rep, "d").output


def test_stub_scores_zero_without_crashing():
    rep = graded("stub")
    assert rep.score == 0
    for x in rep.questions:
        assert x.status == "ok"
        assert x.output.count("not implemented yet") == 1


def test_lumped_mass_is_named():
    rep = graded("ex04_lumped_mass")
    a = q(rep, "a")
    assert a.score == 1.5                    # K right, M wrong at both parameter sets
    assert "mass matrix is lumped, not consistent" in a.output
    assert q(rep, "b").score == 1.0 and "M differs" in q(rep, "b").output
    assert q(rep, "c").score == 0 and q(rep, "d").score == 0
    assert "errors are negative" in q(rep, "d").output and "lumped mass matrix" in q(rep, "d").output
    assert rep.score < 10


def test_missing_factor_L_is_named():
    rep = graded("ex04_missing_L")
    a = q(rep, "a")
    assert a.score == 1.5
    assert "a factor L is missing in the rotational terms of the stiffness matrix K" in a.output
    assert "mass matrix" not in a.output     # M is right
    assert q(rep, "b").score == 1.0 and "K differs" in q(rep, "b").output
    assert rep.score == 2.5


def test_supports_not_applied_is_named():
    rep = graded("ex04_no_supports")
    assert full(rep, "a")
    b = q(rep, "b")
    assert b.score == 1.0                    # right free-beam matrices: half the points
    assert "boundary conditions not applied: the matrices are 8x8" in b.output
    assert "(w1, w4 for a pinned-pinned beam), leaving 6x6" in b.output
    assert "w1, theta1 for a cantilever beam" in b.output
    c = q(rep, "c")
    assert c.score == 0
    assert "boundary conditions not applied: you have rigid-body zero frequencies" in c.output
    assert "rigid-body mode" in q(rep, "d").output and q(rep, "d").score == 0
    assert rep.score == 4


def test_hz_and_pinned_beta_for_cantilever_are_named():
    rep = graded("ex04_hz_and_pi")
    assert full(rep, "a", "b")
    assert q(rep, "c").score == 0 and "these are in Hz: return rad/s" in q(rep, "c").output
    d = q(rep, "d")
    assert d.score == 1                      # the pinned-pinned call is right
    assert "beta L = pi, which is the pinned-pinned value" in d.output
    assert "beta_2 L = 4.6940911330" in d.output
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
            assert graded(name).score < 10, name


# ----------------------------------------------------------------------------
# diagnoses, in-process
# ----------------------------------------------------------------------------

def _payload(x):
    x = np.asarray(x, dtype=float)
    return {"ok": True, "value": {"shape": list(x.shape), "data": x.ravel().tolist()}}


def _question(qid):
    return next(x for x in ex04.questions() if x.id == qid)


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
    def rounded(length, E, I, rho, A, support, mode=1):
        w = [sol.natural_frequencies(n, length, E, I, rho, A, support, mode)[mode - 1] for n in (2, 4, 8)]
        bl = round(sol.BETA_L[support][mode - 1], 3)
        return np.array(w) / (bl**2 * math.sqrt(E * I / (rho * A * length**4))) - 1

    score, fb = _check("d", rounded)
    assert score < ex04.POINTS["d"] and any("ppm off: use beta L to at least 10 digits" in line for line in fb), fb

    def next_mode(length, E, I, rho, A, support, mode=1):
        w = [sol.natural_frequencies(n, length, E, I, rho, A, support, mode)[mode - 1] for n in (2, 4, 8)]
        return np.array(w) / sol.analytic_frequency(length, E, I, rho, A, support, mode + 1) - 1

    score, fb = _check("d", next_mode)
    assert score == 0 and all("the analytic value is that of mode" in line for line in fb), fb


def test_bad_payloads_are_reported():
    qu = _question("a")
    score, fb = qu.check([_payload(np.eye(4)), {"ok": False, "error": "boom"}])
    assert score == 0
    assert any("must return the pair (K, M)" in line for line in fb) and any("boom" in line for line in fb)


def test_listed_and_stub_named():
    assert ex04.EXERCISE.stub == "exercises/ex04_beam_element.py"
    assert (ROOT / ex04.EXERCISE.stub).is_file()
    assert "mutext.rotor" in ex04.EXERCISE.blocked_modules


def test_cli_list_shows_ex04(capsys):
    assert cli.main(["grade", "--list"]) == 0
    out = capsys.readouterr().out
    assert EXERCISE in out and "ex01_two_mass_hinf" in out
