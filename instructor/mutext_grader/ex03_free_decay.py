r"""Grader of exercise ``ex03_free_decay``: free-decay identification of a cart (thesis sec. 3.3.2).

Questions (10 points):

(a1) ``natural_frequency(t, y, cycles)``, 1.5 points: eq. (3.1) in rad/s from
     the peak times of three noise-free records (0.5 points each, 1 %).
(a2) ``damping_ratio(t, y, cycles)``, 1.5 points: eq. (3.2), the logarithmic
     decrement over ``cycles`` cycles divided by ``2 pi cycles`` (0.5 points
     per record, 5 %).
(b1) ``cart_mass(omega_bare, omega_weighted, m_w)``, 1.5 points: eq. (3.3)
     in its correct form :math:`m_c = m_w\omega_w^2/(\omega_c^2-\omega_w^2)`.
(b2) ``stiffness(omega_bare, m_c)``, 1.5 points: eq. (3.4).
(c)  ``damping_coefficient(zeta, m_c, omega)``, 2 points: eq. (3.5).
(d)  ``identify_cart(t_bare, y_bare, t_w, y_w, m_w)``, 2 points: ``(m_c, k, c)``
     from two noisy records of two carts (1/3 point per value; 5 % for the
     mass, which eq. 3.3 makes sensitive to frequency errors, 2 % for the
     stiffness, 5 % for the damping).

Inputs are drawn per run from the generator the grader passes
(:func:`draw`): each cart's mass and stiffness within 30 % of a cart of the
three-mass rig (thesis Table 3.1), its damping ratio in a band where eqs.
3.1/3.2 keep their tolerances (0.008-0.1), the number of cycles, the release
displacement, the added mass (1.4-2.8 times the cart's), the record's length
(near 3 s at 1 kHz) and the noise.  The records are generated with
:func:`mutext.sysid.simulate_free_decay` from these parameters, which are the
reference values: the natural frequency of (a1) is the damped one,
:math:`\omega_n\sqrt{1-\zeta^2}`, which is what eq. (3.1) measures (the
tolerance also accepts :math:`\omega_n`).  The formula questions (b), (c) are
exact (relative tolerance 1e-6).  Submissions may not import
:mod:`mutext.sysid` (it computes the answers).

What earns points: a value within the tolerance of the reference of that
call, and only if the answers vary with the inputs.  Whatever the draw, the
references of a question differ pairwise by more than twice the tolerance,
so one number cannot fit two calls, and a value returned alike for every
call scores 0 for the question (for (d), per quantity).  The draws keep the
arguments away from the answers (the added mass is 1.4-2.8 times the cart's
mass and 15 % clear of its damping coefficient; the release displacement
is no damping ratio), and each record holds a whole number and a part of a
cycle such that the largest bin of a plain FFT is at least 1 % off (on the
bare and the weighted record of (d) in opposite directions), so constants,
zeros, returned arguments and a one-line spectrum peak earn nothing
(``tests/grading_submissions/trivial/ex03_*.py``).

Feedback names the call by number ("record 2 of 3, cycles = 5", "case 1 of
3", "cart 2 of 2, m_w = 1.6 kg": only arguments, never a cart's parameters),
the submitted value and the usual mistakes, never the reference: Hz instead
of rad/s (a factor :math:`2\pi`), the period instead of the frequency, the
decrement not divided by the number of cycles or by :math:`2\pi`, the
thesis's printed eq. (3.3) (which gives :math:`m_c + m_w`), frequencies not
squared.
"""
from __future__ import annotations

import functools
import math

import numpy as np

from .compare import fmt
from .core import Call, Exercise, Question

POINTS = {"a1": 1.5, "a2": 1.5, "b1": 1.5, "b2": 1.5, "c": 2.0, "d": 2.0}
RTOL_FREQ = 0.01       # (a1): the damped and the undamped frequency both pass for zeta <= 0.1
RTOL_ZETA = 0.05       # (a2) and the damping of (d)
RTOL_M = 0.05          # mass of (d): eq. 3.3 amplifies frequency errors (and uses damped frequencies)
RTOL_K = 0.02          # stiffness of (d)
RTOL_EXACT = 1e-6      # formula questions (b), (c)
TWO_PI = 2 * math.pi

# The graded inputs are drawn per run (see :func:`draw`) around the carts of the three-mass rig (thesis
# Table 3.1): mass and stiffness within +-SPREAD of a thesis cart, the damping ratio in a band that keeps
# eqs. 3.1/3.2 within their tolerances, so every draw is as hard as the thesis's carts.
SPREAD = 0.30
#: (m kg, k N/m, band of the damping ratio) of the three noise-free records of (a): cart 1 bare (air
#: damper, heavily damped), cart 2 with 2 kg (lightly damped) and a softer cart.  The bands do not overlap
#: and the records are shuffled, so no value fits every record.
A_CARTS = ((0.8113, 842.3, (0.065, 0.10)), (2.6396, 1648.8, (0.008, 0.02)), (1.5, 400.0, (0.028, 0.05)))
#: (m_c kg, k N/m, band of zeta) of the two carts identified in (d): cart 1 and cart 3 without the air damper
D_CARTS = ((0.8113, 842.3, (0.065, 0.10)), (0.6074, 1192.5, (0.025, 0.05)))
#: thesis carts (m, k) around which the formula cases of (b) and (c) are drawn
FORMULA_CARTS = ((0.8113, 842.3), (0.6074, 1192.5), (1.5, 400.0), (2.6396, 1648.8))
ZETA_RANGE = (0.008, 0.10)     # damping ratios of (c)
MASS_RATIO = (1.4, 2.8)        # added mass / cart mass (the rig: 2 kg on 0.81 kg, 1 kg on 0.61 kg)
MIN_OMEGA_W = 16.0             # rad/s: the weighted cart of (d) still shows 7 cycles in a record
NOISE = 3e-6                   # m, the measurement noise of (d) (the stub states it)
FS = 1000.0                    # Hz, the sampling rate of every record
SEPARATION = 1.15              # pairwise ratio of the references of one question at least (> 2 tolerances)


def exact_values(m, k, c):
    """``(omega_n, omega_d, zeta)`` of ``m x'' + c x' + k x = 0``."""
    wn = math.sqrt(k / m)
    z = c / (2 * math.sqrt(k * m))
    return wn, wn * math.sqrt(1 - z * z), z


@functools.lru_cache(maxsize=32)
def record(m, k, c, x0=0.025, duration=3.0, noise=0.0, seed=None):
    """A record sampled at ``FS`` from rest at ``x0`` (m), as plain lists ``(t, y)``."""
    from mutext.sysid import simulate_free_decay
    t, y = simulate_free_decay(m, k, c, x0=x0, duration=duration, fs=FS, noise=noise, rng=seed)
    return [round(float(v), 6) for v in t], [float(v) for v in y]


# ----------------------------------------------------------------------------
# the draw of the graded inputs
# ----------------------------------------------------------------------------

def _separated(values, ratio=SEPARATION):
    """Every two of ``values`` differ by more than the factor ``ratio``."""
    v = sorted(abs(float(x)) for x in values)
    return all(b > ratio * a for a, b in zip(v, v[1:]))


def _perturbed(rng, m, k):
    return m * rng.uniform(1 - SPREAD, 1 + SPREAD), k * rng.uniform(1 - SPREAD, 1 + SPREAD)


def _duration(rng, wd, fraction=(0.35, 0.65)):
    """A record length within 0.35 s of 3 s that holds a whole number of damped cycles and a
    ``fraction`` more, rounded to the sample: the peak of a plain FFT then falls between two bins,
    at least 1 % off, so that a one-line spectrum peak is not taken for the frequency of eq. 3.1 (a
    fraction below 1/2 puts it in the bin below, above 1/2 in the bin above)."""
    f = wd / TWO_PI
    cycles = math.floor(3.0 * f) + rng.uniform(*fraction)
    if cycles / f > 3.35:
        cycles -= 1.0
    return round(cycles / f * FS) / FS


def _x0(rng):
    """The release displacement (m): 21.5-26 mm, which as a number lies 5 % clear of every damping ratio
    of (a), so that returning ``y[0]`` is not a damping ratio."""
    return round(float(rng.uniform(0.0215, 0.026)), 5)


def draw(rng):
    """The graded inputs of one run, from the numpy Generator ``rng``.

    Returns a dict: ``"a"``, three records ``(m, k, c, cycles, x0, duration)`` (shuffled); ``"b1"``,
    ``(omega_bare, omega_weighted, m_w)``; ``"b2"``, ``(omega_bare, m_c)``; ``"c"``, ``(zeta, m_c, omega)``
    (three cases each); ``"d"``, two carts ``(m_c, k, c, m_w, x0, (duration_bare, duration_weighted),
    (seed_bare, seed_weighted))``.  Whatever the draw, the references of a question differ pairwise by
    more than twice their tolerance, and no input argument equals an answer.
    """
    while True:
        recs = []
        for m0, k0, (z_lo, z_hi) in A_CARTS:
            m, k = _perturbed(rng, m0, k0)
            z = math.exp(rng.uniform(math.log(z_lo), math.log(z_hi)))
            c = 2 * z * math.sqrt(k * m)
            wd = exact_values(m, k, c)[1]
            duration = _duration(rng, wd)
            periods = duration * wd / TWO_PI
            n_max = min(8 if z < 0.06 else 6, int(periods - 1.5))
            cycles = int(rng.integers(3, n_max + 1))
            recs.append((m, k, c, cycles, _x0(rng), duration))
        if _separated([exact_values(*r[:3])[1] for r in recs], 1.05):
            break
    a = [recs[i] for i in rng.permutation(len(recs))]

    def formula_cart():
        m0, k0 = FORMULA_CARTS[int(rng.integers(len(FORMULA_CARTS)))]
        return _perturbed(rng, m0, k0)

    while True:
        b1 = []
        for _ in range(3):
            m_c, k = formula_cart()
            m_w = round(float(rng.uniform(*MASS_RATIO)) * m_c, 2)
            b1.append((round(math.sqrt(k / m_c), 4), round(math.sqrt(k / (m_c + m_w)), 4), m_w))
        if _separated([ref_mass(*x) for x in b1]):
            break
    while True:
        b2 = []
        for _ in range(3):
            m, k = formula_cart()
            b2.append((round(math.sqrt(k / m), 4), round(m, 4)))
        if _separated([w * w * m for w, m in b2]):
            break
    while True:
        cc = []
        for _ in range(3):
            m, k = formula_cart()
            z = math.exp(rng.uniform(*np.log(ZETA_RANGE)))
            cc.append((round(z, 4), round(m, 4), round(math.sqrt(k / m), 4)))
        if _separated([2 * z * m * w for z, m, w in cc]):
            break
    while True:
        d = []
        for m0, k0, (z_lo, z_hi) in D_CARTS:
            while True:
                m_c, k = _perturbed(rng, m0, k0)
                m_w = round(float(rng.uniform(*MASS_RATIO)) * m_c, 2)
                z = math.exp(rng.uniform(math.log(z_lo), math.log(z_hi)))
                c = 2 * z * math.sqrt(k * m_c)
                if math.sqrt(k / (m_c + m_w)) >= MIN_OMEGA_W and _separated([m_w, c]):
                    break
            # the plain FFT's frequency errs low on the bare and high on the weighted record: a one-line
            # spectrum peak does not give the mass of eq. 3.3 by a lucky cancellation
            durations = (_duration(rng, exact_values(m_c, k, c)[1], (0.30, 0.42)),
                         _duration(rng, exact_values(m_c + m_w, k, c)[1], (0.58, 0.70)))
            seeds = tuple(int(s) for s in rng.integers(2**31, size=2))
            d.append((m_c, k, c, m_w, _x0(rng), durations, seeds))
        if all(_separated(vals) for vals in zip(*[x[:3] for x in d])):
            break
    return {"a": a, "b1": b1, "b2": b2, "c": cc, "d": d}


# ----------------------------------------------------------------------------
# helpers
# ----------------------------------------------------------------------------

def _near(x, target, rtol):
    return math.isfinite(x) and abs(x - target) <= rtol * abs(target)


def _about(ratio, target, tol):
    return abs(ratio / target - 1) < tol


def _ratio_hints(ratio, what, cycles=None, tol=0.02):
    """Names of the mistakes that make a value ``ratio`` times the expected one.

    ``tol`` is relative: a hint is given only when the ratio is that close to
    the factor the mistake produces (a factor 2 must match to ``tol / 2``, so
    that an arbitrary value does not look like one)."""
    if not math.isfinite(ratio) or ratio == 0:
        return []
    hints = []
    if _about(ratio, 1 / TWO_PI, tol):
        hints.append(f"the {what} is 1/(2 pi) times the expected one: Hz instead of rad/s? "
                     "(omega = 2 pi f)")
    elif _about(ratio, TWO_PI, tol):
        hints.append(f"the {what} is 2 pi times the expected one")
    elif _about(ratio, 1 / TWO_PI**2, tol):
        hints.append(f"the {what} is 1/(2 pi)^2 times the expected one: a frequency in Hz instead of "
                     "rad/s, squared?")
    elif _about(ratio, TWO_PI**2, tol):
        hints.append(f"the {what} is (2 pi)^2 times the expected one: the frequencies are already in rad/s")
    elif cycles and cycles > 1 and _about(ratio, cycles, max(tol, 0.05)):
        hints.append(f"the {what} is {cycles} times the expected one, the number of cycles: "
                     "divide by N = cycles")
    elif cycles and cycles > 1 and _about(ratio, 1 / cycles, max(tol, 0.05)):
        hints.append(f"the {what} is 1/{cycles} of the expected one: the time between the peaks spans "
                     f"N = {cycles} periods")
    elif _about(ratio, 2, tol / 2) or _about(ratio, 0.5, tol / 2):
        hints.append(f"the {what} is off by a factor 2 ({'too large' if ratio > 1 else 'too small'})")
    elif _about(ratio, -1, tol):
        hints.append(f"the {what} has the wrong sign")
    return hints


def _nan_text(x):
    """Feedback for a value that is not a finite number (``None`` if it is one)."""
    if math.isnan(x):
        return "the answer is NaN (not a number): a 0/0 somewhere?"
    if math.isinf(x):
        return "the answer is infinite: a division by zero?"
    return None


def _same_for_all(values, refs, rtol):
    """Every call returned the same finite value (to ``rtol``) although the references differ by more than
    twice ``rtol``: a constant, not an answer computed from the inputs."""
    if len(values) < 2 or any(v is None or not math.isfinite(v) for v in values):
        return False
    v0 = values[0]
    return (all(abs(v - v0) <= rtol * max(abs(v0), 1e-300) for v in values)
            and _separated(refs, (1 + rtol) / (1 - rtol)))


CONSTANT_TEXT = ("every call returned the same value although the inputs differ: the answer must be computed "
                 "from the arguments, 0 points")


def _float_score(outcomes, calls, expected, rtol, what, per_call, hint=None):
    """Score calls that return one float each; ``expected[i]`` is the reference of call ``i``.

    The feedback names the submitted value and the mistake it shows, never the reference; a value
    returned for every call alike scores 0 (:func:`_same_for_all`)."""
    score, fb, values = 0.0, [], []
    for oc, call, ref in zip(outcomes, calls, expected):
        if not oc["ok"]:
            fb.append(f"[{call.label}] {oc['error']}")
            values.append(None)
            continue
        x = float(oc["value"])
        values.append(x)
        if _near(x, ref, rtol):
            score += per_call
            continue
        if _nan_text(x):
            fb.append(f"[{call.label}] {what}: got {fmt(x)}; {_nan_text(x)}")
            continue
        within = f"{rtol:.0e} relative" if rtol < 1e-3 else f"{rtol:.0%}"
        msg = f"[{call.label}] {what}: got {fmt(x)}, not within {within} of the right value"
        tol = min(0.02, max(1e-4, 2 * rtol))
        extra = (hint(x, ref, call) if hint else None) or _ratio_hints(x / ref if ref else math.nan, what,
                                                                        tol=tol)
        fb.append(msg + ("; " + "; ".join(extra) if extra else ""))
    if _same_for_all(values, expected, rtol):
        return 0.0, [f"{what}: {CONSTANT_TEXT}"]
    if not fb:
        fb = [f"correct: all {len(calls)} values within {rtol:.0e} relative" if rtol < 1e-3 else
              f"correct: all {len(calls)} values within {rtol:.0%}"]
    return score, fb


# ----------------------------------------------------------------------------
# (a) frequency and damping ratio from a record
# ----------------------------------------------------------------------------

def _freq_hint(x, ref, call):
    ratio = x / ref
    if abs(x * ref / TWO_PI - 1) < 0.02:
        return ["this is the period 2 pi/omega in s: return omega = 2 pi N / (t_N - t_0)"]
    return _ratio_hints(ratio, "frequency", call.cycles)


def _zeta_hint(x, ref, call):
    N = call.cycles
    ratio = x / ref
    # the mistakes and the factors they give; the nearest within 5 % is named (N = 6 is near 2 pi)
    known = [(TWO_PI * N, f"this is ln(y_0/y_N), the decrement over {N} cycles: divide by 2 pi N"),
             (TWO_PI, "this is the logarithmic decrement delta per cycle: zeta = delta / (2 pi)"),
             (N, f"zeta is {N} times too large: the decrement ln(y_0/y_N) spans N = {N} cycles, "
                 "divide it by N (eq. 3.2)"),
             (1 / math.log(10), "zeta is 1/ln(10) of the expected one: use the natural logarithm, not log10"),
             (-1.0, "zeta is negative: the ratio is y_0 / y_N (earlier peak over later peak)")]
    off, text = min((abs(ratio / f - 1), text) for f, text in known)
    if off < 0.05:
        return [text]
    return _ratio_hints(ratio, "damping ratio")


class _RecordCall(Call):
    def __init__(self, label, args, cycles):
        super().__init__(label, args)
        self.cycles = cycles


def _check_a1(outcomes, calls):
    refs = [exact_values(*c.params)[1] for c in calls]
    return _float_score(outcomes, calls, refs, RTOL_FREQ, "frequency (rad/s)",
                        POINTS["a1"] / len(calls), _freq_hint)


def _check_a2(outcomes, calls):
    refs = [exact_values(*c.params)[2] for c in calls]
    return _float_score(outcomes, calls, refs, RTOL_ZETA, "damping ratio", POINTS["a2"] / len(calls),
                        _zeta_hint)


# ----------------------------------------------------------------------------
# (b), (c) formulas
# ----------------------------------------------------------------------------

def ref_mass(wc, ww, m_w):
    return m_w * ww**2 / (wc**2 - ww**2)


def _mass_hint(x, ref, call):
    wc, ww, m_w = call.args
    if _near(x, m_w * wc**2 / (wc**2 - ww**2), 1e-6):
        return ["this is m_c + m_w: the thesis prints omega_c^2 in the numerator of eq. 3.3, but with "
                "omega_c^2 = k/m_c and omega_w^2 = k/(m_c + m_w) the cart mass is "
                "m_c = m_w omega_w^2 / (omega_c^2 - omega_w^2)"]
    if _near(x, m_w * ww / (wc - ww), 1e-6):
        return ["the frequencies are not squared: omega^2 = k/m"]
    if x < 0:
        return ["a negative mass: are omega_bare (the bare cart, the faster one) and omega_weighted swapped?"]
    return None


def _stiff_hint(x, ref, call):
    w, m = call.args
    if _near(x, w * m, 1e-6):
        return ["the frequency is not squared: k = omega^2 m"]
    return None


def _damp_hint(x, ref, call):
    z, m, w = call.args
    if _near(x, 2 * z * math.sqrt(m) * w, 1e-6) or _near(x, 2 * z * m * math.sqrt(w), 1e-6):
        return ["c = 2 zeta m omega (= 2 zeta sqrt(k m)), no square roots"]
    if _near(x, z * m * w, 1e-6):
        return ["the factor 2 is missing: c = 2 zeta m omega"]
    if _near(x, 2 * z * w / m, 1e-6) or _near(x, 2 * z * m / w, 1e-6):
        return ["check the units: c (N s/m) = 2 zeta m omega"]
    return None


# ----------------------------------------------------------------------------
# (d) identification from two records
# ----------------------------------------------------------------------------

NAMES = ("m_c (kg)", "k (N/m)", "c (N s/m)")


def _check_d(outcomes, calls):
    per = POINTS["d"] / (3 * len(calls))
    tols = (RTOL_M, RTOL_K, RTOL_ZETA)
    got = np.full((len(calls), 3), np.nan)        # the submitted values, for the rule on constants
    ok = np.zeros((len(calls), 3), dtype=bool)
    fb = []
    for j, (oc, call) in enumerate(zip(outcomes, calls)):
        if not oc["ok"]:
            fb.append(f"[{call.label}] {oc['error']}")
            continue
        try:
            x = np.asarray(oc["value"]["data"], dtype=float).ravel()
        except Exception as exc:   # noqa: BLE001 - malformed payload is the submission's fault
            fb.append(f"[{call.label}] the returned value is not an array of numbers ({exc})")
            continue
        if x.size != 3:
            fb.append(f"[{call.label}] identify_cart() must return the three numbers (m_c, k, c), "
                      f"got {x.size} value(s)")
            continue
        got[j] = x
        m_c, k, c, m_w = call.params
        refs = (m_c, k, c)
        for i, (name, v, ref, tol) in enumerate(zip(NAMES, x, refs, tols)):
            if _near(float(v), ref, tol):
                ok[j, i] = True
                continue
            msg = f"[{call.label}] {name}: got {fmt(v)}, not within {tol:.0%} of the cart's value"
            hints = []
            if _nan_text(float(v)):
                hints.append(_nan_text(float(v)))
            elif i == 0 and _near(float(v), m_c + m_w, tol):
                hints.append("this is m_c + m_w: the thesis's printed eq. 3.3 has omega_c^2 in the numerator; "
                             "m_c = m_w omega_w^2 / (omega_c^2 - omega_w^2)")
            elif i == 1 and _near(float(v), k * (m_c + m_w) / m_c, tol):
                hints.append("k = omega_c^2 (m_c + m_w): it follows from a mass m_c + m_w (see m_c)")
            elif i == 2 and _near(float(v), c * (m_c + m_w) / m_c, RTOL_ZETA):
                hints.append("c follows from a mass m_c + m_w (see m_c)")
            else:
                ratio = float(v) / ref
                n = round(ratio)
                if i == 2 and 2 <= n <= 40 and abs(ratio / n - 1) < RTOL_ZETA and abs(ratio - 2) > 0.04:
                    hints.append(f"c is about {n} times too large: is the decrement ln(y_0/y_N) divided by the "
                                 "number of cycles N? (eq. 3.2)")
                else:
                    hints += _ratio_hints(ratio, name.split()[0])
            fb.append(msg + ("; " + "; ".join(hints) if hints else ""))
    for i, (name, tol) in enumerate(zip(NAMES, tols)):
        refs = [call.params[i] for call in calls]
        if _same_for_all([float(v) for v in got[:, i]], refs, tol):
            ok[:, i] = False
            fb.append(f"{name}: {CONSTANT_TEXT}")
    if not fb:
        fb = ["correct: m_c within 5 %, k within 2 %, c within 5 % for both carts"]
    return per * int(ok.sum()), fb


def questions(rng=None):
    """The six questions with inputs drawn from ``rng`` (:func:`draw`; a fresh generator if None).

    The records are simulated here, not in the child; the labels name only what the function receives
    (the number of cycles, the added mass), never the cart's parameters."""
    cases = draw(np.random.default_rng() if rng is None else rng)
    a_calls = []
    for i, (m, k, c, N, x0, duration) in enumerate(cases["a"]):
        t, y = record(m, k, c, x0, duration)
        call = _RecordCall(f"record {i + 1} of {len(cases['a'])}, cycles = {N}", [t, y, N], N)
        call.params = (m, k, c)
        a_calls.append(call)
    b1_calls = [Call(f"case {i + 1} of {len(cases['b1'])}", list(args)) for i, args in enumerate(cases["b1"])]
    b2_calls = [Call(f"case {i + 1} of {len(cases['b2'])}", list(args)) for i, args in enumerate(cases["b2"])]
    c_calls = [Call(f"case {i + 1} of {len(cases['c'])}", list(args)) for i, args in enumerate(cases["c"])]
    d_calls = []
    for i, (m_c, k, c, m_w, x0, (dur0, dur1), (seed0, seed1)) in enumerate(cases["d"]):
        t0, y0 = record(m_c, k, c, x0, dur0, NOISE, seed0)
        t1, y1 = record(m_c + m_w, k, c, x0, dur1, NOISE, seed1)
        call = Call(f"cart {i + 1} of {len(cases['d'])}, m_w = {m_w:g} kg", [t0, y0, t1, y1, m_w])
        call.params = (m_c, k, c, m_w)
        d_calls.append(call)
    b1_refs = [ref_mass(*a) for a in cases["b1"]]
    b2_refs = [w**2 * m for w, m in cases["b2"]]
    c_refs = [2 * z * m * w for z, m, w in cases["c"]]
    return [
        Question("a1", "natural_frequency", "frequency from peak times, eq. 3.1 (rad/s)", POINTS["a1"], "float",
                 a_calls, lambda oc: _check_a1(oc, a_calls)),
        Question("a2", "damping_ratio", "damping ratio from the log decrement, eq. 3.2", POINTS["a2"], "float",
                 a_calls, lambda oc: _check_a2(oc, a_calls)),
        Question("b1", "cart_mass", "cart mass from the added mass, eq. 3.3", POINTS["b1"], "float", b1_calls,
                 lambda oc: _float_score(oc, b1_calls, b1_refs, RTOL_EXACT, "m_c (kg)",
                                         POINTS["b1"] / len(b1_calls), _mass_hint)),
        Question("b2", "stiffness", "equivalent stiffness, eq. 3.4", POINTS["b2"], "float", b2_calls,
                 lambda oc: _float_score(oc, b2_calls, b2_refs, RTOL_EXACT, "k (N/m)",
                                         POINTS["b2"] / len(b2_calls), _stiff_hint)),
        Question("c", "damping_coefficient", "damping coefficient, eq. 3.5", POINTS["c"], "float", c_calls,
                 lambda oc: _float_score(oc, c_calls, c_refs, RTOL_EXACT, "c (N s/m)",
                                         POINTS["c"] / len(c_calls), _damp_hint)),
        Question("d", "identify_cart", "(m_c, k, c) from a bare and a weighted decay", POINTS["d"], "array",
                 d_calls, lambda oc: _check_d(oc, d_calls)),
    ]


EXERCISE = Exercise("ex03_free_decay", "Free-decay identification of a cart: frequency, damping, mass, stiffness",
                    questions, stub="exercises/ex03_free_decay.py", blocked_modules=("mutext.sysid", "mutext.examples"))
