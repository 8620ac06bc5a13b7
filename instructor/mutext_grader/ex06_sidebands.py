r"""Grader of exercise ``ex06_sidebands``: sidebands of a cracked rotor at speed (book: cracked-rotor chapter).

Questions (10 points):

(a) ``sideband_frequencies``, 2.5 points: the candidates :math:`f_n - kF`,
    :math:`k = \pm` orders, inside a band, sorted, duplicates merged, on five
    cases (three random ones, the rig's rotor at the run's speed, and
    commensurate frequencies whose candidates coincide and fall on the band
    edges), 0.5 each, to 1e-9 Hz.
(b) ``sideband_size``, 2.5 points: the local detector of the docstring (a
    complex quadratic fitted to :math:`1/H` around the candidate, centre left
    out) on four sweeps, 0.5 each, within 0.1 % of the computation here; and
    0.5 for behaving as a detector: more than 10 x the noise at a breathing
    crack's 1X sideband of a low-noise sweep AND below 5 x the noise at the
    same frequency of the healthy rotor (both, so no constant earns it).
(c) ``classify``, 5 points: eight sweeps, 0.625 each; the reference is the
    verdict of the model that made the sweep ("once per revolution" for a
    breathing crack, "twice per revolution" for an always-open one, "none" for
    the healthy rotor, softer bearings or a crack that does not turn; returned
    as its index in ``VERDICTS``), not the output of any detector.

Inputs are drawn from the generator the grader is given (:mod:`mutext_grader.core`):
the running speed (9, 10 or 11 Hz), the depths of the cracks and the stiffness
of the softer bearings (:data:`CHOICES`), the model behind each sweep of (c)
with the number of each verdict (1 to 3 "none", at least 2 of each crack),
every sweep's noise level (5e-4 to 1e-3 in (c), drawn alike whatever the model,
so the noise argument says nothing of the verdict) and noise, the sidebands
and frequencies of (a) and (b).  A noisy sweep is kept only when the recipe
of the exercise's docstring classifies it as its model (and, in (b), when the
detector sees the sideband above 20 x the noise and the healthy rotor below 3
x the noise): a noise that makes a sweep ambiguous is drawn again, the
tolerances are never loosened.

Scoring of (c): a sweep's 0.625 points count only if the submission is also
right on a sweep of another verdict, so a constant verdict (always "none",
always "once per revolution", ...) scores 0.

Feedback never prints a reference value or what made a sweep: calls are
"case n of N" or "sweep n of N" with their arguments (frequency, noise), and
a wrong verdict is answered with what to check, not with the right one.  It
names the usual mistakes: the speed taken in rad/s, one sign of k only,
duplicates kept, the centre points left in the fit, the baseline fitted to H
instead of 1/H, a threshold that ignores the noise level.

The sweeps are made here, in the grading process, with
:func:`mutext.rig.measure_rotor` (seeded noise, added by
:func:`mutext.rig.with_noise`): the exact sweep of a time-periodic rotor
costs one to two seconds, so it is computed once per model and process
(keyed by the drawn speed, depth or bearing stiffness: at most
:func:`n_models` of them) and the noisy copies are drawn from it.
"""
from __future__ import annotations

import math
import threading

import numpy as np

from .compare import as_array, fmt, returned
from .core import Call, Exercise, Question

POINTS = {"a": 2.5, "b": 2.5, "c": 5.0}
VERDICTS = ("none", "once per revolution", "twice per revolution")
SPEED_HZ = 10.0            # the rig's speed (the model file's)
SPEEDS_HZ = (9.0, 10.0, 11.0)
NOISE = 5e-4               # the least noise of the sweeps of (b) and (c) ...
HIGH_NOISE = 1e-3          # ... and the most (log-uniform in between, drawn alike for every model)
LOW_NOISE = 1e-4           # the two sweeps of (b)'s detector check
CENTRE_HZ = 1.0
ATOL_A = 1e-9
RTOL_B = 1e-3
N_C = 8                    # sweeps of (c)

#: the generating model of each sweep and the verdict it implies
TRUTH = {"breathing": "once per revolution", "open": "twice per revolution", "healthy": "none",
         "bearings": "none", "fixed_crack": "none"}
#: what is drawn of each model: the crack's depth ratio, or the stiffness of both (softer) ball bearings [N/m]
CHOICES = {"healthy": (None,), "breathing": (0.5,), "open": (0.3, 0.35, 0.4), "fixed_crack": (0.3, 0.4),
           "bearings": (5.0e6, 6.0e6, 7.0e6)}
#: the model's parameter when none is given (the book's rig)
DEFAULT = {"healthy": None, "breathing": 0.4, "open": 0.4, "fixed_crack": 0.4, "bearings": 6.0e6}
#: the recipe of the exercise (classify's docstring)
MODE_SEARCH, CLEARANCE_HZ, HALF_WIDTH_HZ, THRESHOLD = 0.05, 6.0, 3.0, 5.0

_LOCK = threading.Lock()
_CACHE: dict = {}


def n_models():
    """How many exact sweeps the draws can ask for (the size of the process's cache)."""
    return len(SPEEDS_HZ) * sum(len(v) for v in CHOICES.values())


def _cached(key, make):
    """``make()`` once per process (exact sweeps, frequencies), one at a time, BLAS on one thread.

    Two gradings may run in threads of one process (the tests do): the lock keeps them from making
    the same sweep twice, and one BLAS thread keeps the eigenvalue solvers from spinning against each
    other on a busy machine (:func:`mutext.lti.blas_single_thread`)."""
    from mutext.lti import blas_single_thread
    with _LOCK:
        if key not in _CACHE:
            with blas_single_thread():
                _CACHE[key] = make()
        return _CACHE[key]


def model(name, speed=SPEED_HZ, param=None):
    """The rotor model called ``name`` (keys of :data:`TRUTH`) at ``speed`` [Hz]: the rig's rotor file
    with a crack of depth ratio ``param`` at the rig's crack station (breathing by the Mayes law, always
    open, or not turning with the shaft), or both ball bearings of stiffness ``param``."""
    from mutext.rotor import data_path, loads_model
    from mutext.rotor.crack import RIG_CRACK_STATION
    param = DEFAULT[name] if param is None else param
    with open(data_path("rotor.toml"), encoding="utf-8") as fh:
        text = fh.read()
    assert "speed_rpm = 600" in text and text.count("stiffness = 1.0e7") == 2
    text = text.replace("speed_rpm = 600", f"speed_rpm = {60 * float(speed):g}")
    if name == "bearings":
        text = text.replace("stiffness = 1.0e7", f"stiffness = {float(param):.6g}")
    elif name != "healthy":
        law = {"breathing": "mayes", "open": "open", "fixed_crack": None}[name]
        text += f"\n[[crack]]\nstation = {RIG_CRACK_STATION}\ndepth_ratio = {float(param)!r}\norientation = 0.0\n"
        if law is not None:
            text += f"breathing = {law!r}\n"
    return loads_model(text, source=f"rotor.toml: {name}", base_dir=data_path(""))


def _exact(name, speed, param):
    """(the exact sweep i12 -> x13 as an FRF, the model's natural frequencies at speed), kept."""
    param = DEFAULT[name] if param is None else param

    def make():
        from mutext.rig import measure_rotor
        m = model(name, speed, param)
        return measure_rotor(m, "i12", "x13"), tuple(float(x) for x in m.natural_frequencies(n=8))
    return _cached(("exact", name, float(speed), param), make)


def natural_frequencies(name="healthy", speed=SPEED_HZ, param=None):
    """A model's eight lowest natural frequencies at speed [Hz]; the healthy one's (to 1e-4 Hz) are what
    a student is given."""
    fn = _exact(name, speed, param)[1]
    return tuple(round(x, 4) for x in fn) if name == "healthy" else fn


def sweep(name, noise, seed, speed=SPEED_HZ, param=None):
    """``(f, H)`` of the rig's sweep i12 -> x13 of a model with seeded noise.

    The same numbers as ``measure_rotor(model, "i12", "x13", noise=noise, rng=seed)``, which adds the
    noise to the exact sweep with :func:`mutext.rig.with_noise`; the exact sweep (the costly harmonic
    balance) is computed once per model and shared by its noisy copies."""
    from mutext.rig import with_noise
    d = with_noise(_exact(name, speed, param)[0], noise, rng=seed)
    return np.asarray(d.freq_hz, float).copy(), np.asarray(d.response, complex).copy()


def _seed(rng):
    return int(rng.integers(2 ** 62))


def _noise_level(rng):
    return float(f"{math.exp(rng.uniform(math.log(NOISE), math.log(HIGH_NOISE))):.2g}")


# ----------------------------------------------------------------------------
# (a)
# ----------------------------------------------------------------------------

def candidates(fn, speed, orders, f_min, f_max, *, signs=(1, -1), dedupe=True, closed=True):
    """``f_n - k F`` for ``k`` in ``signs x orders`` inside the band, sorted, duplicates within 1e-9 merged."""
    c = np.sort(np.array([x - s * abs(int(k)) * speed for x in fn for k in orders for s in signs], float))
    c = c[(c >= f_min) & (c <= f_max)] if closed else c[(c > f_min) & (c < f_max)]
    out = []
    for x in c:
        if not dedupe or not out or x - out[-1] > 1e-9:
            out.append(float(x))
    return np.array(out)


ORDERS = ([1, 2, 3], [2], [1, 3], [1], [1, 2], [3], [2, 3])


def _a_cases(rng, speed, fn_rig):
    """(fn, speed, orders, f_min, f_max) of the five cases."""
    out = []
    picks = rng.choice(len(ORDERS), size=3, replace=False)
    for n in range(3):
        while True:
            fn = np.round(np.sort(rng.uniform(15.0, 400.0, int(rng.integers(3, 7)))), 6)
            sp = round(float(rng.uniform(4.0, 40.0)), 6)
            lo = round(float(rng.uniform(0.0, 50.0)), 6)
            hi = round(lo + float(rng.uniform(150.0, 400.0)), 6)
            if candidates(fn, sp, ORDERS[picks[n]], lo, hi).size >= 3:
                break
        out.append((fn.tolist(), sp, ORDERS[picks[n]], lo, hi))
    lo, hi = float(rng.integers(20, 31)), float(rng.integers(200, 231))
    out.append((list(fn_rig), float(speed), ORDERS[int(rng.integers(len(ORDERS)))], lo, hi))
    # commensurate: modes at multiples of the speed, the band's ends on candidates, candidates coinciding
    while True:
        sp = float(rng.integers(6, 15))
        fn = [sp * a for a in sorted(rng.choice([2.5, 3.0, 4.0, 5.0, 6.0, 7.5, 8.0, 10.0, 12.0], 4, replace=False))]
        lo, hi = fn[0] - sp, fn[-1] - sp
        if candidates(fn, sp, [1, 2, 3], lo, hi).size < candidates(fn, sp, [1, 2, 3], lo, hi, dedupe=False).size:
            break
    out.append((fn, sp, [1, 2, 3], lo, hi))
    idx = rng.permutation(len(out))
    return [out[i] for i in idx]


def _check_a(outcomes, calls):
    score, fb = 0.0, []
    per = POINTS["a"] / len(calls)
    for call, tag, x in returned(outcomes, calls, fb, as_array, "sideband_frequencies()"):
        x = x.ravel()
        ref = call.ref
        if x.size == ref.size and np.all(np.abs(x - ref) <= ATOL_A):
            score += per
            continue
        if x.size == ref.size and np.all(np.abs(np.sort(x) - ref) <= ATOL_A):
            fb.append(f"{tag} the right frequencies, but not sorted in increasing order")
            continue
        msg = f"{tag} not the candidates f_n - k F of the band (to {ATOL_A:.0e} Hz)"
        if x.size != ref.size:
            msg += f": {'too many' if x.size > ref.size else 'too few'} values"
        for name, alt in call.alternatives.items():
            if x.size == alt.size and np.all(np.abs(np.sort(x) - alt) <= ATOL_A):
                msg += f"; this is {name}"
                break
        fb.append(msg)
    if not fb:
        fb = [f"correct: all {len(calls)} sets of candidates, to {ATOL_A:.0e} Hz"]
    return score, fb


# ----------------------------------------------------------------------------
# (b)
# ----------------------------------------------------------------------------

def size(f, h, fc, half_width, *, invert=True, exclude_centre=True, relative_to="baseline", degree=2):
    """The reference detector of (b); the keywords give the usual mistakes."""
    y = 1.0 / h if invert else h
    x = f - fc
    window = np.abs(x) <= half_width
    centre = np.abs(x) <= CENTRE_HZ
    fit = window & ~centre if exclude_centre else window
    coef = np.linalg.lstsq(np.vander(x[fit], degree + 1), y[fit], rcond=None)[0]
    base = np.vander(x[centre], degree + 1) @ coef
    scale = {"baseline": np.abs(base), "data": np.abs(y[centre]), "none": 1.0}[relative_to]
    return float(np.max(np.abs(y[centre] - base) / scale))


def _inside(f, fc, hw):
    return f.min() <= fc - hw and fc + hw <= f.max()


def b_cases(rng, speed, params):
    """(name, noise, seed, candidate [Hz], half width [Hz], detector role) of the four sweeps of (b):
    a breathing crack's 1X sideband at low noise (the detector must see it), the healthy rotor there
    (it must not), an open crack's 2X sideband, softer bearings near a mode."""
    f = sweep("healthy", 0.0, 0, speed)[0]
    for _ in range(20):
        fb = natural_frequencies("breathing", speed, params["breathing"])
        hw = float(rng.choice([2.5, 3.0, 3.5]))
        ks = [k for k in (1, -1) if _inside(f, fb[0] - k * speed, hw)]
        fc = round(fb[0] - ks[int(rng.integers(len(ks)))] * speed, 2)
        for _ in range(10):
            s1, s2 = _seed(rng), _seed(rng)
            big = size(*sweep("breathing", LOW_NOISE, s1, speed, params["breathing"]), fc, hw)
            small = size(*sweep("healthy", LOW_NOISE, s2, speed), fc, hw)
            if big > 20 * LOW_NOISE and small < 3 * LOW_NOISE:
                break
        else:
            continue
        break
    else:   # pragma: no cover - the tests draw many
        raise RuntimeError("no breathing-crack sideband the detector tells from the healthy rotor")
    out = [("breathing", LOW_NOISE, s1, fc, hw, "large"), ("healthy", LOW_NOISE, s2, fc, hw, "small")]
    fo = natural_frequencies("open", speed, params["open"])
    hw = float(rng.choice([2.0, 2.5, 3.0]))
    opts = [round(x - k * speed, 2) for x in (fo[0], fo[2]) for k in (2, -2) if _inside(f, x - k * speed, hw)]
    out.append(("open", _noise_level(rng), _seed(rng), opts[int(rng.integers(len(opts)))], hw, None))
    fbear = natural_frequencies("bearings", speed, params["bearings"])
    hw = float(rng.choice([3.0, 3.5, 4.0]))
    opts = [round(x - k * speed, 2) for x in (fbear[0], fbear[2]) for k in (1, -1)
            if _inside(f, x - k * speed, hw)]
    out.append(("bearings", _noise_level(rng), _seed(rng), opts[int(rng.integers(len(opts)))], hw, None))
    return out


def _check_b(outcomes, calls):
    score, fb = 0.0, []
    per = (POINTS["b"] - 0.5) / len(calls)
    values = {}
    for call, tag, value in returned(outcomes, calls, fb):
        x = float(value)
        values[call.label] = x
        ref = call.ref
        if math.isfinite(x) and abs(x - ref) <= RTOL_B * abs(ref):
            score += per
            continue
        msg = f"{tag} not within {RTOL_B:.1%} of the recipe's size"
        for name, alt in call.alternatives.items():
            if math.isfinite(x) and abs(x - alt) <= RTOL_B * abs(alt):
                msg += f"; this is {name}"
                break
        else:
            if math.isnan(x):
                msg += "; the answer is NaN"
        fb.append(msg)
    # the detector: large at a true sideband AND small where there is none (a constant is never both)
    told = 0
    for call in calls:
        if call.role is None:
            continue
        x = values.get(call.label)
        if x is None or not math.isfinite(x):
            continue              # the call failed or returned NaN: said above
        if (call.role == "large" and x > 10 * call.noise) or (call.role == "small" and 0 <= x < 5 * call.noise):
            told += 1
        elif call.role == "large":
            fb.append(f"[{call.label}] detector: a breathing crack's sideband is here, your size {fmt(x)} is not "
                      f"above 10 x the noise of this sweep ({fmt(10 * call.noise)})")
        else:
            fb.append(f"[{call.label}] detector: there is no sideband here, your size {fmt(x)} is not below "
                      f"5 x the noise of this sweep ({fmt(5 * call.noise)}): does the baseline follow the "
                      "resonance's tail? (fit 1/H, not H)")
    if told == 2:
        score += 0.5
    elif told == 1:
        fb.append("detector: the half point goes to sizes that are both above 10 x the noise at the sideband "
                  "and below 5 x the noise where there is none")
    if not fb:
        fb = [f"correct: all {len(calls)} sizes within {RTOL_B:.1%}, and they tell a sideband from none"]
    return score, fb


# ----------------------------------------------------------------------------
# (c)
# ----------------------------------------------------------------------------

def recipe_verdict(f, h, fn, speed, noise):
    """The verdict of the recipe in ``classify``'s docstring (the draws of (c) are kept when it is the
    model's)."""
    modes = set()
    for x in fn:
        near = np.abs(f - x) <= MODE_SEARCH * x
        if f.min() < x < f.max() and near.any():
            modes.add(float(f[np.flatnonzero(near)[np.argmax(np.abs(h[near]))]]))
    modes = sorted(modes)
    found = set()
    for fm in modes:
        for k in (1, -1, 2, -2, 3, -3):
            fc = fm - k * speed
            if not _inside(f, fc, HALF_WIDTH_HZ) or min(abs(fc - x) for x in modes + list(fn)) < CLEARANCE_HZ:
                continue
            if size(f, h, fc, HALF_WIDTH_HZ) > THRESHOLD * noise:
                found.add(abs(k))
    return "once per revolution" if found & {1, 3} else "twice per revolution" if 2 in found else "none"


def c_cases(rng, speed, params, fn):
    """(name, noise, seed) of the sweeps of (c): 1-3 of the time-invariant models, at least two of each
    crack; every noise level drawn alike, a noise seed drawn again while the recipe misreads the sweep."""
    n_none = int(rng.integers(1, 4))
    n_once = int(rng.integers(2, N_C - n_none - 1))
    names = ["breathing"] * n_once + ["open"] * (N_C - n_none - n_once)
    names += [("healthy", "bearings", "fixed_crack")[int(rng.integers(3))] for _ in range(n_none)]
    out = []
    for name in (names[i] for i in rng.permutation(N_C)):
        noise = _noise_level(rng)
        for _ in range(30):
            seed = _seed(rng)
            f, h = sweep(name, noise, seed, speed, params[name])
            if recipe_verdict(f, h, fn, speed, noise) == TRUTH[name]:
                break
        else:   # pragma: no cover - the tests draw many
            raise RuntimeError(f"no sweep of the {name} model the recipe reads right at noise {noise:g}")
        out.append((name, noise, seed))
    return out


def _check_c(outcomes, calls):
    per = POINTS["c"] / len(calls)
    right, fb = {v: 0 for v in VERDICTS}, []
    for call, tag, value in returned(outcomes, calls, fb):
        x = float(value)
        want = call.verdict
        idx = round(x) if math.isfinite(x) else -1
        if not (math.isfinite(x) and abs(x - idx) < 1e-9 and 0 <= idx < len(VERDICTS)):
            fb.append(f"{tag} classify() must return 0, 1 or 2 (the index in VERDICTS), got {fmt(x)}")
            continue
        got = VERDICTS[idx]
        if got == want:
            right[want] += 1
            continue
        if got == "none":
            msg = (f"{tag} '{got}' is not the verdict of the model that made this sweep: the sidebands of a crack "
                   "are several times the threshold in these data: are the candidates placed at the data's "
                   "resonances, f_n - k F with F in Hz, and is the threshold 5 x noise?")
        else:
            msg = (f"{tag} '{got}' is not the verdict of the model that made this sweep: are candidates within "
                   "6 Hz of a resonance skipped, is your threshold proportional to the noise (5 x noise), and "
                   "does order 1 or 3 mean once per revolution, order 2 alone twice?")
        fb.append(msg)
    counted = [v for v in VERDICTS if right[v] and any(right[w] for w in VERDICTS if w != v)]
    score = per * sum(right[v] for v in counted)
    if sum(right.values()) and not counted:
        fb.append("the sweeps classified right all have one verdict: they count only with a sweep of another "
                  "verdict classified right too")
    if not fb:
        fb = [f"correct: all {len(calls)} sweeps classified"]
    return score, fb


def draw(rng):
    """The speed and the models' parameters of a grading."""
    speed = float(SPEEDS_HZ[int(rng.integers(len(SPEEDS_HZ)))])
    return speed, {name: v[int(rng.integers(len(v)))] for name, v in CHOICES.items()}


def questions(rng=None):
    """The three questions, drawn from ``rng``; the sweeps and reference answers are made here, not in the
    child."""
    rng = np.random.default_rng() if rng is None else rng
    speed, params = draw(rng)
    fn = list(natural_frequencies("healthy", speed))
    a_calls = []
    cases = _a_cases(rng, speed, fn)
    for n, (fa, sp, orders, lo, hi) in enumerate(cases):
        call = Call(f"case {n + 1} of {len(cases)}", [list(map(float, fa)), float(sp), list(orders), float(lo),
                                                     float(hi)])
        call.ref = candidates(fa, sp, orders, lo, hi)
        call.alternatives = {
            "the speed taken in rad/s (f_n - k 2 pi F): F is already in Hz":
                candidates(fa, 2 * np.pi * sp, orders, lo, hi),
            "only k > 0 (the sidebands below the modes): k runs over + and - each order":
                candidates(fa, sp, orders, lo, hi, signs=(1,)),
            "only k < 0 (the sidebands above the modes): k runs over + and - each order":
                candidates(fa, sp, orders, lo, hi, signs=(-1,)),
            "with the duplicates kept: merge candidates closer than 1e-9 Hz":
                candidates(fa, sp, orders, lo, hi, dedupe=False),
            "the band taken as open: f_min and f_max themselves belong to it":
                candidates(fa, sp, orders, lo, hi, closed=False),
            "the orders 1, 2 and 3 whatever is asked: use only the given orders":
                candidates(fa, sp, [1, 2, 3], lo, hi),
            "with the modes themselves (k = 0) included": np.array(sorted(set(
                candidates(fa, sp, orders, lo, hi).tolist() + [float(x) for x in fa if lo <= x <= hi]))),
        }
        a_calls.append(call)
    b_calls = []
    cases = b_cases(rng, speed, params)
    for n, (name, noise, seed, fc, hw, role) in enumerate(cases):
        f, h = sweep(name, noise, seed, speed, params[name])
        call = Call(f"sweep {n + 1} of {len(cases)}, f = {fc:g} Hz, half width {hw:g} Hz",
                    [f.tolist(), h.real.tolist(), h.imag.tolist(), fc, hw])
        call.ref = size(f, h, fc, hw)
        call.role, call.noise = role, noise
        call.alternatives = {
            "the size with the centre points in the fit: leave |f - f_c| <= 1 Hz out, or the baseline "
            "absorbs the sideband": size(f, h, fc, hw, exclude_centre=False),
            "a baseline fitted to H: fit the quadratic to 1/H": size(f, h, fc, hw, invert=False),
            "the deviation relative to the data: divide by |baseline|": size(f, h, fc, hw, relative_to="data"),
            "the absolute deviation: divide by |baseline|": size(f, h, fc, hw, relative_to="none"),
            "a straight-line baseline: the polynomial has degree 2": size(f, h, fc, hw, degree=1),
        }
        b_calls.append(call)
    c_calls = []
    cases = c_cases(rng, speed, params, fn)
    for n, (name, noise, seed) in enumerate(cases):
        f, h = sweep(name, noise, seed, speed, params[name])
        call = Call(f"sweep {n + 1} of {len(cases)}, noise {noise:g}",
                    [f.tolist(), h.real.tolist(), h.imag.tolist(), fn, speed, noise])
        call.verdict, call.noise, call.model = TRUTH[name], noise, name
        c_calls.append(call)
    return [
        Question("a", "sideband_frequencies", "where the sidebands must appear", POINTS["a"], "array", a_calls,
                 lambda oc: _check_a(oc, a_calls)),
        Question("b", "sideband_size", "size of a local departure from a smooth baseline", POINTS["b"], "float",
                 b_calls, lambda oc: _check_b(oc, b_calls)),
        Question("c", "classify", "once per revolution, twice per revolution or none", POINTS["c"], "float",
                 c_calls, lambda oc: _check_c(oc, c_calls)),
    ]


EXERCISE = Exercise("ex06_sidebands", "Sidebands: predict and find the sidebands of a cracked rotor at speed",
                    questions, stub="exercises/ex06_sidebands.py",
                    blocked_modules=("mutext.diagnose", "mutext.rotor", "mutext.rig", "mutext.report",
                                     "mutext.commands"))
