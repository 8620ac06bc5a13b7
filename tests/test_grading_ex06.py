"""Autograder of exercise ex06_sidebands: drawn inputs, scores and feedback of the reference, the stub,
common mistakes and submissions that do not solve."""
import re
import threading
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

from grading_harness import full, q
from mutext_grader import ex06_sidebands as ex06
from mutext_grader import grade
from mutext_grader.compare import fmt

ROOT = Path(__file__).resolve().parents[1]
SUBS = Path(__file__).resolve().parent / "grading_submissions"
PATHS = {
    "reference": ROOT / "instructor" / "mutext_grader" / "solutions" / "ex06_sidebands.py",
    "stub": ROOT / "exercises" / "ex06_sidebands.py",
    **{p.stem: p for p in SUBS.glob("ex06_*.py")},
    **{p.stem: p for p in (SUBS / "trivial").glob("ex06_*.py")},
}
#: the seed of most checks: 10 Hz, and a time-invariant sweep noisy enough for a fixed threshold to fail
SEED = 6
#: two more seeds for the reference solution (slow: the other two speeds, other models)
MORE_SEEDS = (0, 14)
TRIVIAL = ("ex06_always_none", "ex06_constant_verdicts", "ex06_noise_rule")

_pool = ThreadPoolExecutor(max_workers=2)
_futures = {}
_lock = threading.Lock()


def graded(name, seed=SEED):
    """The report of a submission graded on the inputs drawn from ``seed`` (every submission of the
    default seed is started, two at a time, the first time one is asked for)."""
    with _lock:
        if not _futures:
            for n in sorted(PATHS, key=lambda n: n != "reference"):
                _futures[(n, SEED)] = _pool.submit(grade, "ex06_sidebands", PATHS[n], 60.0, seed=SEED)
        if (name, seed) not in _futures:
            _futures[(name, seed)] = _pool.submit(grade, "ex06_sidebands", PATHS[name], 60.0, seed=seed)
        return _futures[(name, seed)].result()


_drawn = {}


def drawn(seed=SEED):
    if seed not in _drawn:
        _drawn[seed] = {x.id: x for x in ex06.questions(np.random.default_rng(seed))}
    return _drawn[seed]


def test_reference_solution_scores_full_marks():
    rep = graded("reference")
    assert rep.max_score == 10
    assert rep.score == 10, rep.text()


@pytest.mark.slow
@pytest.mark.parametrize("seed", MORE_SEEDS)
def test_reference_solution_scores_full_marks_on_other_seeds(seed):
    assert ex06.draw(np.random.default_rng(seed))[0] != ex06.draw(np.random.default_rng(SEED))[0]
    rep = graded("reference", seed)
    assert rep.score == 10, rep.text()


@pytest.mark.slow
def test_reference_solution_is_right_on_many_draws():
    """In process, without the confined child: every question of 12 more draws scored in full."""
    from mutext_grader.solutions import ex06_sidebands as sol

    def payload(v):
        if np.isscalar(v):
            return float(v)
        v = np.asarray(v, float)
        return {"data": v.ravel().tolist(), "shape": list(v.shape)}
    for seed in range(100, 112):
        for question in ex06.questions(np.random.default_rng(seed)):
            fn = getattr(sol, question.function)
            outcomes = [{"ok": True, "value": payload(fn(*c.args))} for c in question.calls]
            score, fb = question.check(outcomes)
            assert score == pytest.approx(question.points), (seed, question.id, fb)


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
    """A fixed threshold of 0.25 % (5 x the least noise) is the recipe run as if the noise were always
    5e-4: it loses exactly the sweeps that this reading gets wrong (here a time-invariant one, noisier)."""
    rep = graded("ex06_fixed_threshold")
    c = q(rep, "c")
    calls = drawn()["c"].calls
    wrong = [x for x in calls if ex06.recipe_verdict(np.asarray(x.args[0]), np.asarray(x.args[1])
                                                     + 1j * np.asarray(x.args[2]), x.args[3], x.args[4],
                                                     2.5e-3 / ex06.THRESHOLD) != x.verdict]
    assert wrong and all(x.noise > ex06.NOISE for x in wrong)
    assert c.score == pytest.approx(c.max_score * (1 - len(wrong) / len(calls)), abs=0.01)
    assert "proportional to the noise" in c.output
    assert full(rep, "a", "b")


@pytest.mark.parametrize("name", TRIVIAL)
def test_submissions_that_do_not_solve_score_nothing(name):
    """One verdict everywhere, the modes handed back, constant sizes: nothing.  A verdict read from the
    noise argument is a guess (the noise is drawn alike for every model): at most what guessing earns."""
    rep = graded(name)
    assert all(x.status == "ok" for x in rep.questions)
    assert q(rep, "a").score == 0 and q(rep, "b").score == 0, rep.text()
    c = q(rep, "c")
    if name == "ex06_noise_rule":
        assert c.score <= c.max_score / 2 + 1e-9, rep.text()
    else:
        assert c.score == 0, rep.text()


def test_a_constant_verdict_scores_nothing_on_any_draw():
    """The (c) check alone: each constant verdict on this draw and on made-up verdict sets scores 0."""
    c = drawn()["c"]
    for idx in range(3):
        assert c.check([{"ok": True, "value": float(idx)}] * len(c.calls))[0] == 0
    assert c.check([{"ok": True, "value": float(ex06.VERDICTS.index(x.verdict))} for x in c.calls])[0] == 5


def test_verdicts_are_mixed_and_their_numbers_drawn():
    """Each draw has 1-3 time-invariant sweeps and at least two of each crack; the counts vary."""
    seen = set()
    # the draw of the models comes before any sweep: read it with the recipe always agreeing
    for seed in range(40):
        rng = np.random.default_rng(seed)
        names = _models_drawn(rng)
        n = [ex06.TRUTH[x] for x in names]
        assert 1 <= n.count("none") <= 3 and n.count("once per revolution") >= 2
        assert n.count("twice per revolution") >= 2 and len(n) == ex06.N_C
        seen.add(tuple(sorted(n)))
    assert len(seen) >= 5


def _models_drawn(rng):
    """The models of (c) that ``c_cases`` draws from ``rng``, with the recipe taken as always right."""
    from unittest import mock
    names = []

    def fake_sweep(name, *args):
        names.append(name)
        return None, None
    with mock.patch.object(ex06, "sweep", fake_sweep), \
            mock.patch.object(ex06, "recipe_verdict", lambda f, h, fn, s, n: ex06.TRUTH[names[-1]]):
        ex06.c_cases(rng, 10.0, {k: v[0] for k, v in ex06.CHOICES.items()}, [])
    return names


def test_noise_level_says_nothing_of_the_model():
    """The noise levels of (c) are drawn alike for every model: over many draws the levels of the
    time-invariant sweeps and of the cracks have the same spread."""
    from unittest import mock
    levels = {"none": [], "crack": []}
    for seed in range(150):
        names, noises = [], []

        def fake_sweep(name, noise, *args):
            names.append(name)
            noises.append(noise)
            return None, None
        with mock.patch.object(ex06, "sweep", fake_sweep), \
                mock.patch.object(ex06, "recipe_verdict", lambda f, h, fn, s, n: ex06.TRUTH[names[-1]]):
            ex06.c_cases(np.random.default_rng(seed), 10.0, {k: v[0] for k, v in ex06.CHOICES.items()}, [])
        for name, noise in zip(names, noises):
            levels["none" if ex06.TRUTH[name] == "none" else "crack"].append(noise)
    a, b = np.log(levels["none"]), np.log(levels["crack"])
    assert abs(np.mean(a) - np.mean(b)) < 0.1 and abs(np.std(a) - np.std(b)) < 0.1
    assert min(levels["none"]) >= ex06.NOISE and max(levels["crack"]) <= ex06.HIGH_NOISE


def test_inputs_are_drawn_from_the_seed():
    """The same seed gives the same inputs (a regrade gives the same score); another seed others."""
    a = ex06.questions(np.random.default_rng(SEED))
    other = 16          # the same speed and models as SEED (their exact sweeps are made once): all else differs
    assert ex06.draw(np.random.default_rng(other)) == ex06.draw(np.random.default_rng(SEED))
    b, c = drawn(SEED), drawn(other)
    for x in a:
        assert [y.args for y in x.calls] == [y.args for y in b[x.id].calls]
        for y, z in zip(b[x.id].calls, c[x.id].calls):
            assert y.args != z.args, x.id


def test_feedback_names_no_hidden_parameter():
    """Wrong answers are described by what to check: no reference value, model or right verdict."""
    qs = drawn()
    for name in ("ex06_rad_per_s", "ex06_centre_in_fit", "ex06_fixed_threshold") + TRIVIAL:
        text = graded(name).text()
        for call in qs["b"].calls:
            assert fmt(call.ref) not in text
        for call in qs["a"].calls:
            for x in call.ref:
                assert f"{fmt(x)} Hz" not in text and f"be {fmt(x)}" not in text
        c = q(graded(name), "c").output
        assert not re.search(r"breathing|open crack|healthy|bearing|expected", c), c
        for call, line in ((x, ln) for x in qs["c"].calls for ln in c.splitlines()
                           if ln.startswith(f"[{x.label}]")):
            assert f"'{call.verdict}'" not in line, line


def test_blocked_modules():
    """The modules that make the sweeps or find sidebands cannot be imported by a submission."""
    for m in ("mutext.diagnose", "mutext.rotor", "mutext.rig"):
        assert m in ex06.EXERCISE.blocked_modules


def test_sweeps_differ_by_their_sidebands_not_by_noise():
    """At the breathing crack's 1X sideband drawn for (b) the detector sees far more than the noise; on the
    healthy rotor at the same frequency, no more than the noise (the premise of (b) and (c))."""
    b = drawn()["b"].calls
    big, small = b[0], b[1]
    assert (big.role, small.role) == ("large", "small") and big.args[3] == small.args[3]
    f, h = np.asarray(big.args[0]), np.asarray(big.args[1]) + 1j * np.asarray(big.args[2])
    g, h0 = np.asarray(small.args[0]), np.asarray(small.args[1]) + 1j * np.asarray(small.args[2])
    fc, hw = big.args[3], big.args[4]
    assert np.array_equal(f, g)
    assert ex06.size(f, h, fc, hw) > 20 * ex06.LOW_NOISE
    assert ex06.size(g, h0, fc, hw) < 5 * ex06.LOW_NOISE
    # a baseline fitted to H itself finds a "sideband" on the healthy rotor too, above the level the
    # detector must see at the crack: H is not quadratic this near a resonance, 1/H is
    assert ex06.size(g, h0, fc, hw, invert=False) > 20 * ex06.LOW_NOISE


def test_candidates_formula():
    c = ex06.candidates([30.0, 50.0], 10.0, [1, 2], 20.0, 60.0)
    assert c.tolist() == [20.0, 30.0, 40.0, 50.0, 60.0]   # 40 from both modes, once; 20 and 60 on the edges


def test_sweeps_are_those_of_measure_rotor():
    """A sweep with its noise is bit for bit what measure_rotor gives for the same model and seed."""
    from mutext.rig import measure_rotor
    speed, params = ex06.draw(np.random.default_rng(SEED))
    f, h = ex06.sweep("bearings", ex06.NOISE, 76, speed, params["bearings"])
    d = measure_rotor(ex06.model("bearings", speed, params["bearings"]), "i12", "x13", noise=ex06.NOISE, rng=76)
    assert np.array_equal(f, d.freq_hz) and np.array_equal(h, d.response)


def test_frequencies_of_the_grader_are_the_models():
    """The natural frequencies given to students are the healthy model's at the drawn speed, and the
    candidates of (b) are sidebands of the drawn models' modes."""
    speed, params = ex06.draw(np.random.default_rng(SEED))
    healthy = ex06.model("healthy", speed).natural_frequencies(n=8)
    qs = drawn()
    assert np.allclose(qs["c"].calls[0].args[3], healthy, rtol=0, atol=1e-4)
    assert qs["c"].calls[0].args[4] == speed
    for call, name, ks in zip(qs["b"].calls, ("breathing", "breathing", "open", "bearings"),
                              ((1, -1), (1, -1), (2, -2), (1, -1))):
        fn = ex06.natural_frequencies(name, speed, params[name])
        assert min(abs(call.args[3] - (x - k * speed)) for x in fn for k in ks) <= 0.005
