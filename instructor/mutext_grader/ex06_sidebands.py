r"""Grader of exercise ``ex06_sidebands``: sidebands of a cracked rotor at speed (book: cracked-rotor chapter).

Questions (10 points):

(a) ``sideband_frequencies``, 2.5 points: the candidates :math:`f_n - kF`,
    :math:`k = \pm` orders, inside a band, sorted, duplicates merged, on five
    cases (three random ones drawn here with a fixed seed, the rig's rotor,
    and commensurate frequencies whose candidates coincide and fall on the
    band edges), 0.5 each, to 1e-9 Hz.
(b) ``sideband_size``, 2.5 points: the local detector of the docstring (a
    complex quadratic fitted to :math:`1/H` around the candidate, centre left
    out) on four sweeps, 0.5 each, within 0.1 % of the computation here; and
    0.5 for behaving as a detector: more than 10 x the noise at the breathing
    crack's 1X sideband of a low-noise sweep, below 5 x the noise at the same
    frequency of the healthy rotor.
(c) ``classify``, 5 points: eight sweeps (a breathing crack, an open crack,
    the healthy rotor, softer bearings, a crack that does not turn; noise
    5e-4, two of the time-invariant ones 2e-3), 0.625 each; the reference is
    the verdict of the model that made the sweep ("once per revolution",
    "twice per revolution", "none", returned as its index in ``VERDICTS``),
    not the output of any detector.

The sweeps are made here, in the grading process, with
:func:`mutext.rig.measure_rotor` (seeded noise), and kept for the rest of the
process: the exact sweep of a time-periodic rotor costs one to two seconds, so
it is computed once per model and the noisy copies are drawn from it.
Feedback names the usual mistakes: the speed taken in rad/s, one sign of k
only, duplicates kept, the centre points left in the fit, the baseline fitted
to H instead of 1/H, a threshold that ignores the noise level.
"""
from __future__ import annotations

import math
import threading

import numpy as np

from .compare import as_array, fmt, returned
from .core import Call, Exercise, Question

POINTS = {"a": 2.5, "b": 2.5, "c": 5.0}
VERDICTS = ("none", "once per revolution", "twice per revolution")
SPEED_HZ = 10.0
NOISE = 5e-4              # the sweeps of (c)
LOW_NOISE = 1e-4          # the two sweeps of (b)'s detector check
HIGH_NOISE = 2e-3         # two sweeps of (c) where a threshold that ignores the noise fails
CENTRE_HZ = 1.0
ATOL_A = 1e-9
RTOL_B = 1e-3

#: the generating model of each sweep and the verdict it implies
TRUTH = {"breathing": "once per revolution", "open": "twice per revolution", "healthy": "none",
         "bearings": "none", "fixed_crack": "none"}
#: (label, model, noise, seed) of the sweeps of (c); labels do not name the model
C_CASES = [("sweep 1", "breathing", NOISE, 71), ("sweep 2", "healthy", NOISE, 72),
           ("sweep 3", "open", NOISE, 73), ("sweep 4", "fixed_crack", HIGH_NOISE, 74),
           ("sweep 5", "breathing", NOISE, 75), ("sweep 6", "bearings", NOISE, 76),
           ("sweep 7", "open", NOISE, 77), ("sweep 8", "healthy", HIGH_NOISE, 78)]

#: ``healthy_rotor().natural_frequencies(n=8)`` to 1e-4 Hz (checked by the tests; an eigenvalue
#: problem of the full rotor costs seconds on a busy machine, so it is not solved at each grading)
HEALTHY_HZ = (33.8893, 33.9219, 191.0806, 195.4479, 354.2389, 354.4950, 502.1387, 512.2187)

_LOCK = threading.Lock()
_CACHE: dict = {}


def _cached(key, make):
    """``make()`` once per process (models, frequencies, sweeps), one at a time, BLAS on one thread.

    Two gradings may run in threads of one process (the tests do): the lock keeps them from making
    the same sweep twice, and one BLAS thread keeps the eigenvalue solvers from spinning against each
    other on a busy machine (:func:`mutext.lti.blas_single_thread`)."""
    from mutext.lti import blas_single_thread
    with _LOCK:
        if key not in _CACHE:
            with blas_single_thread():
                _CACHE[key] = make()
        return _CACHE[key]


def _make_model(name):
    from mutext.examples.cracked_rotor import cracked_rotor, healthy_rotor
    if name == "healthy":
        return healthy_rotor()
    if name == "breathing":
        return cracked_rotor(0.4, breathing="mayes")
    if name == "open":
        return cracked_rotor(0.4, breathing="open")
    if name == "fixed_crack":           # the same crack, not turning with the shaft: time-invariant
        return cracked_rotor(0.4, breathing=None)
    if name == "bearings":              # both ball bearings 40 % softer: time-invariant
        from mutext.rotor import data_path, loads_model
        with open(data_path("rotor.toml"), encoding="utf-8") as fh:
            text = fh.read()
        return loads_model(text.replace("stiffness = 1.0e7", "stiffness = 6.0e6"),
                           source="rotor.toml with softer bearings", base_dir=data_path(""))
    raise KeyError(name)


def model(name):
    """The rotor model that makes the sweeps called ``name`` (keys of :data:`TRUTH`)."""
    return _cached(("model", name), lambda: _make_model(name))


def natural_frequencies():
    """The healthy model's eight lowest natural frequencies at speed [Hz] (what a student is given)."""
    return HEALTHY_HZ


def sweep(name, noise, seed):
    """``(f, H)`` of the rig's sweep i12 -> x13 of a model with seeded noise, kept for the process.

    The same numbers as ``measure_rotor(model, "i12", "x13", noise=noise, rng=seed)``, which adds the
    noise to the exact sweep with :func:`mutext.rig.with_noise`; the exact sweep (the costly harmonic
    balance) is computed once per model and shared by its noisy copies."""
    from mutext.rig import measure_rotor, with_noise
    m = model(name)
    exact = _cached(("exact", name), lambda: measure_rotor(m, "i12", "x13"))

    def noisy():
        d = with_noise(exact, noise, rng=seed)
        return np.asarray(d.freq_hz, float).copy(), np.asarray(d.response, complex).copy()
    return _cached(("sweep", name, float(noise), int(seed)), noisy)


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


def _a_cases():
    rng = np.random.default_rng(6061)
    out = []
    for n in range(3):
        fn = np.sort(rng.uniform(15.0, 400.0, int(rng.integers(3, 7))))
        speed = float(rng.uniform(4.0, 40.0))
        orders = [[1, 2, 3], [2], [1, 3]][n]
        lo = float(rng.uniform(0.0, 50.0))
        out.append((f"random case {n + 1}", fn.tolist(), speed, orders, lo, lo + float(rng.uniform(150.0, 400.0))))
    out.append(("the rig's rotor at 10 Hz, 20-225 Hz", list(natural_frequencies()), SPEED_HZ, [1, 2, 3], 20.0,
                225.0))
    out.append(("modes at 30, 50, 75, 120 Hz, 10 Hz (coinciding candidates, band edges)", [30.0, 50.0, 75.0, 120.0],
                10.0, [1, 2, 3], 20.0, 110.0))
    return out


def _check_a(outcomes, calls):
    score, fb = 0.0, []
    per = POINTS["a"] / len(calls)
    for call, tag, x in returned(outcomes, calls, fb, as_array, "sideband_frequencies()"):
        x = x.ravel()
        ref = call.ref
        if x.size == ref.size and np.all(np.abs(x - ref) <= ATOL_A):
            score += per
            continue
        msg = f"{tag} expected {ref.size} frequencies"
        if x.size == ref.size and np.all(np.abs(np.sort(x) - ref) <= ATOL_A):
            fb.append(f"{msg}: the right ones, but not sorted in increasing order")
            continue
        if x.size != ref.size:
            msg += f", got {x.size}"
        else:
            k = int(np.argmax(np.abs(x - ref)))
            msg += f"; value {k + 1} should be {fmt(ref[k])} Hz, got {fmt(x[k])}"
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


#: (label, model, noise, seed, candidate [Hz], half width [Hz], detector role) of (b); the candidates
#: are the models' natural frequencies (to 0.01 Hz, checked by the tests) shifted by k F
B_CASES = [("breathing crack, noise 1e-4, its 1X sideband k = -1", "breathing", LOW_NOISE, 61, 43.73, 3.0,
            "large"),     # first mode of the breathing crack (averaged) 33.73 Hz, + F
           ("healthy rotor, noise 1e-4, the same frequency", "healthy", LOW_NOISE, 62, 43.73, 3.0, "small"),
           ("open crack, noise 5e-4, its 2X sideband k = -2", "open", NOISE, 73, 53.48, 2.5,
            None),        # first mode of the open crack (averaged) 33.48 Hz, + 2 F
           ("softer bearings, noise 5e-4, near the second mode", "bearings", NOISE, 76, 177.29, 4.0,
            None)]        # third natural frequency of the softer-bearing rotor 187.29 Hz, - F


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
        msg = f"{tag} expected {fmt(ref)} (within {RTOL_B:.1%}), got {fmt(x)}"
        for name, alt in call.alternatives.items():
            if math.isfinite(x) and abs(x - alt) <= RTOL_B * abs(alt):
                msg += f"; this is {name}"
                break
        else:
            if math.isnan(x):
                msg += "; the answer is NaN"
        fb.append(msg)
    # the detector: large at a true sideband, small where there is none
    for call in calls:
        if call.role is None:
            continue
        x = values.get(call.label)
        if x is None or not math.isfinite(x):
            continue              # the call failed or returned NaN: said above
        if (call.role == "large" and x > 10 * call.noise) or (call.role == "small" and 0 <= x < 5 * call.noise):
            score += 0.25
        elif call.role == "large":
            fb.append(f"[{call.label}] detector: a sideband of about {fmt(call.ref)} of the response is here, "
                      f"your size {fmt(x)} is not above 10 x the noise ({fmt(10 * call.noise)})")
        else:
            fb.append(f"[{call.label}] detector: there is no sideband here, your size {fmt(x)} is not below "
                      f"5 x the noise ({fmt(5 * call.noise)}): does the baseline follow the resonance's "
                      "tail? (fit 1/H, not H)")
    if not fb:
        fb = [f"correct: all {len(calls)} sizes within {RTOL_B:.1%}, and they tell a sideband from none"]
    return score, fb


# ----------------------------------------------------------------------------
# (c)
# ----------------------------------------------------------------------------

def _check_c(outcomes, calls):
    per = POINTS["c"] / len(calls)
    score, fb = 0.0, []
    for call, tag, value in returned(outcomes, calls, fb):
        x = float(value)
        want = call.verdict
        idx = round(x) if math.isfinite(x) else -1
        if not (math.isfinite(x) and abs(x - idx) < 1e-9 and 0 <= idx < len(VERDICTS)):
            fb.append(f"{tag} classify() must return 0, 1 or 2 (the index in VERDICTS), got {fmt(x)}")
            continue
        got = VERDICTS[idx]
        if got == want:
            score += per
            continue
        msg = f"{tag} expected '{want}', got '{got}'"
        if want == "none" and call.noise >= HIGH_NOISE:
            msg += (f"; the rotor is time-invariant and this sweep is noisier ({fmt(call.noise)}): is your "
                    "threshold proportional to the noise (5 x noise)?")
        elif want == "none":
            msg += ("; the rotor is time-invariant: are candidates within 6 Hz of a resonance skipped, and is the "
                    "threshold 5 x noise?")
        elif got == "none":
            msg += ("; the sidebands of the first mode are several times the threshold here: are the candidates "
                    "placed at the data's resonance, f_n - k F with F in Hz?")
        elif want == "once per revolution":
            msg += "; the k = +-1 sidebands of the first mode are in these data: is order 1 tested?"
        else:
            msg += ("; only k = +-2 sidebands are in these data: is a candidate near a resonance (closer than 6 Hz) "
                    "taken for a sideband, or the threshold below 5 x noise?")
        fb.append(msg)
    if not fb:
        fb = [f"correct: all {len(calls)} sweeps classified"]
    return score, fb


def questions(rng=None):
    """The three questions; the sweeps and reference answers are made here, not in the child."""
    a_calls = []
    for label, fn, speed, orders, lo, hi in _a_cases():
        call = Call(label, [list(map(float, fn)), float(speed), list(orders), float(lo), float(hi)])
        call.ref = candidates(fn, speed, orders, lo, hi)
        call.alternatives = {
            "the speed taken in rad/s (f_n - k 2 pi F): F is already in Hz":
                candidates(fn, 2 * np.pi * speed, orders, lo, hi),
            "only k > 0 (the sidebands below the modes): k runs over + and - each order":
                candidates(fn, speed, orders, lo, hi, signs=(1,)),
            "only k < 0 (the sidebands above the modes): k runs over + and - each order":
                candidates(fn, speed, orders, lo, hi, signs=(-1,)),
            "with the duplicates kept: merge candidates closer than 1e-9 Hz":
                candidates(fn, speed, orders, lo, hi, dedupe=False),
            "the band taken as open: f_min and f_max themselves belong to it":
                candidates(fn, speed, orders, lo, hi, closed=False),
            "the orders 1, 2 and 3 whatever is asked: use only the given orders":
                candidates(fn, speed, [1, 2, 3], lo, hi),
            "with the modes themselves (k = 0) included": np.array(sorted(set(
                candidates(fn, speed, orders, lo, hi).tolist()
                + [float(x) for x in fn if lo <= x <= hi]))),
        }
        a_calls.append(call)
    b_calls = []
    for label, name, noise, seed, fc, hw, role in B_CASES:
        f, h = sweep(name, noise, seed)
        call = Call(f"{label}, f = {fc:g} Hz, half width {hw:g} Hz",
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
    fn = list(natural_frequencies())
    c_calls = []
    for label, name, noise, seed in C_CASES:
        f, h = sweep(name, noise, seed)
        call = Call(f"{label}, noise {noise:g}", [f.tolist(), h.real.tolist(), h.imag.tolist(), fn, SPEED_HZ,
                                                  noise])
        call.verdict, call.noise = TRUTH[name], noise
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
