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

The records are generated with :func:`mutext.sysid.simulate_free_decay`
from known parameters, which are the reference values: the natural
frequency of (a1) is the damped one, :math:`\omega_n\sqrt{1-\zeta^2}`, which is
what eq. (3.1) measures (the tolerance also accepts :math:`\omega_n`).  The
formula questions (b), (c) are exact (relative tolerance 1e-6).  Submissions
may not import :mod:`mutext.sysid` (it computes the answers).  Feedback
names the usual mistakes: Hz instead of rad/s (a factor :math:`2\pi`), the
period instead of the frequency, the decrement not divided by the number of
cycles or by :math:`2\pi`, the thesis's printed eq. (3.3) (which gives
:math:`m_c + m_w`), frequencies not squared.
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

#: (label, m, k, c, cycles) of the noise-free records of (a): carts of the three-mass rig (Table 3.1)
A_RECORDS = [
    ("cart 1 bare (m = 0.8113 kg, k = 842.3 N/m, c = 5.2992 N s/m), 5 cycles", 0.8113, 842.3, 5.2992, 5),
    ("cart 2 with 2 kg (m = 2.6396 kg, k = 1648.8 N/m, c = 1.9467 N s/m), 8 cycles", 2.6396, 1648.8, 1.9467, 8),
    ("a softer cart (m = 1.5 kg, k = 400 N/m, c = 3 N s/m), 4 cycles", 1.5, 400.0, 3.0, 4),
]
#: (label, m_c, k, c, m_w, noise, seed) of the two identifications of (d)
D_CARTS = [
    ("cart 1 (m_c = 0.8113 kg, k = 842.3 N/m, c = 5.2992 N s/m), m_w = 2 kg", 0.8113, 842.3, 5.2992, 2.0,
     3e-6, 31),
    ("cart 3 without the air damper (m_c = 0.6074 kg, k = 1192.5 N/m, c = 1.9297 N s/m), m_w = 1 kg",
     0.6074, 1192.5, 1.9297, 1.0, 3e-6, 32),
]
#: (omega_bare, omega_weighted, m_w) of (b1), rad/s and kg
B1_CASES = [(32.2212, 17.3075, 2.0), (44.3096, 27.2377, 1.0), (25.0, 20.0, 0.5)]
#: (omega_bare, m_c) of (b2)
B2_CASES = [(32.2212, 0.8113), (44.3096, 0.6074), (16.33, 1.5)]
#: (zeta, m_c, omega) of (c)
C_CASES = [(0.1016, 0.8113, 32.2212), (0.0148, 2.6396, 24.99), (0.0612, 1.5, 16.33)]


def exact_values(m, k, c):
    """``(omega_n, omega_d, zeta)`` of ``m x'' + c x' + k x = 0``."""
    wn = math.sqrt(k / m)
    z = c / (2 * math.sqrt(k * m))
    return wn, wn * math.sqrt(1 - z * z), z


@functools.lru_cache(maxsize=16)
def record(m, k, c, noise=0.0, seed=None):
    """A 3 s record sampled at 1 kHz from rest at 25 mm, as plain lists ``(t, y)``."""
    from mutext.sysid import simulate_free_decay
    t, y = simulate_free_decay(m, k, c, x0=0.025, duration=3.0, fs=1000.0, noise=noise, rng=seed)
    return [round(float(v), 6) for v in t], [float(v) for v in y]


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
        hints.append(f"the {what} is {fmt(ratio)} times the expected one: a factor 2")
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


def _float_score(outcomes, calls, expected, rtol, what, per_call, hint=None):
    """Score calls that return one float each; ``expected[i]`` is the reference of call ``i``."""
    score, fb = 0.0, []
    for oc, call, ref in zip(outcomes, calls, expected):
        if not oc["ok"]:
            fb.append(f"[{call.label}] {oc['error']}")
            continue
        x = float(oc["value"])
        if _near(x, ref, rtol):
            score += per_call
            continue
        msg = f"[{call.label}] {what}: expected {fmt(ref)}, got {fmt(x)}"
        if _nan_text(x):
            fb.append(f"{msg}; {_nan_text(x)}")
            continue
        tol = min(0.02, max(1e-4, 2 * rtol))
        extra = (hint(x, ref, call) if hint else None) or _ratio_hints(x / ref if ref else math.nan, what,
                                                                        tol=tol)
        fb.append(msg + ("; " + "; ".join(extra) if extra else ""))
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
    if abs(ratio / (TWO_PI * N) - 1) < 0.05:
        return [f"this is ln(y_0/y_N), the decrement over {N} cycles: divide by 2 pi N"]
    if abs(ratio / TWO_PI - 1) < 0.05:
        return ["this is the logarithmic decrement delta per cycle: zeta = delta / (2 pi)"]
    if abs(ratio / N - 1) < 0.05:
        return [f"zeta is {N} times too large: the decrement ln(y_0/y_N) spans N = {N} cycles, "
                "divide it by N (eq. 3.2)"]
    if abs(ratio * math.log(10) - 1) < 0.05:
        return ["zeta is 1/ln(10) of the expected one: use the natural logarithm, not log10"]
    if abs(ratio + 1) < 0.05:
        return ["zeta is negative: the ratio is y_0 / y_N (earlier peak over later peak)"]
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
    score, fb = 0.0, []
    for oc, call in zip(outcomes, calls):
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
        m_c, k, c, m_w = call.params
        refs = (m_c, k, c)
        tols = (RTOL_M, RTOL_K, RTOL_ZETA)
        for i, (name, v, ref, tol) in enumerate(zip(NAMES, x, refs, tols)):
            if _near(float(v), ref, tol):
                score += per
                continue
            msg = f"[{call.label}] {name}: expected {fmt(ref)} within {tol:.0%}, got {fmt(v)}"
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
    if not fb:
        fb = ["correct: m_c within 5 %, k within 2 %, c within 5 % for both carts"]
    return score, fb


def questions(rng=None):
    """The six questions with their test inputs (the records are simulated here, not in the child)."""
    a_calls = []
    for label, m, k, c, N in A_RECORDS:
        t, y = record(m, k, c)
        call = _RecordCall(label, [t, y, N], N)
        call.params = (m, k, c)
        a_calls.append(call)
    b1_calls = [Call(f"omega_bare = {wc:g} rad/s, omega_weighted = {ww:g} rad/s, m_w = {mw:g} kg",
                     [wc, ww, mw]) for wc, ww, mw in B1_CASES]
    b2_calls = [Call(f"omega_bare = {w:g} rad/s, m_c = {m:g} kg", [w, m]) for w, m in B2_CASES]
    c_calls = [Call(f"zeta = {z:g}, m_c = {m:g} kg, omega = {w:g} rad/s", [z, m, w]) for z, m, w in C_CASES]
    d_calls = []
    for label, m_c, k, c, m_w, noise, seed in D_CARTS:
        t0, y0 = record(m_c, k, c, noise, seed)
        t1, y1 = record(m_c + m_w, k, c, noise, seed + 100)
        call = Call(label, [t0, y0, t1, y1, m_w])
        call.params = (m_c, k, c, m_w)
        d_calls.append(call)
    b1_refs = [ref_mass(*a) for a in B1_CASES]
    b2_refs = [w**2 * m for w, m in B2_CASES]
    c_refs = [2 * z * m * w for z, m, w in C_CASES]
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
