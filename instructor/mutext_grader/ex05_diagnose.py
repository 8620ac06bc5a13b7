r"""Grader of exercise ``ex05_diagnose``: find the effect hidden in measured FRFs (book: diagnosis chapter).

Questions (10 points):

(a) ``log_misfit``, 1.5 points: the RSS of the complex log ratio on three
    channel pairs (relative tolerance 1e-6); one pair has a phase difference
    near pi, where the difference of the logs of unwrapped phases goes wrong.
(b) ``response_with_grounded_spring``, 2 points: the response with an added
    grounded spring on two chains (1e-6 relative, as a direct solve gives).
(c) ``fit_grounded_spring``, 2 points: the stiffness of a hidden grounded
    spring from one noisy channel (two cases, 2 %).
(d) ``find_effect``, 4.5 points: four hidden cases (a grounded spring, an
    added mass, a grounded damper, none) on the three-mass rig and the
    four-storey frame, 1 % noise: 0.75 points for the kind and the place of
    each case, 0.375 for the size within 10 % ("none" earns both parts).

The chains are the shipped model files read by :func:`mutext.hide.plain_chain`
(plain numpy, no finite-element code); the data are made here, in the
grading process, with seeded noise, and the true effects are the reference
answers.  Feedback names the usual mistakes: Hz taken for rad/s, the phase
wrapped wrongly, a spring added between two masses instead of to the ground,
the station given 0-based, the right place with the wrong kind.
"""
from __future__ import annotations

import functools
import math

import numpy as np

from mutext.response import frequency_grid
from .compare import as_array, fmt, returned
from .core import Call, Exercise, Question

POINTS = {"a": 1.5, "b": 2.0, "c": 2.0, "d": 4.5}
KINDS = ("none", "stiffness", "mass", "damping")
RTOL_EXACT = 1e-6
RTOL_FIT = 0.02
RTOL_SIZE = 0.10
NOISE = 0.01

#: (label, example, kind, 1-based mass, size, seed) of the hidden cases of (d)
D_CASES = [
    ("four-storey frame, case 1", "four_story", "stiffness", 3, 300.0, 51),
    ("three-mass rig, case 2", "three_mass", "mass", 1, 0.25, 52),
    ("four-storey frame, case 3", "four_story", "damping", 2, 3.0, 53),
    ("three-mass rig, case 4", "three_mass", "none", 0, 0.0, 54),
]
#: (label, example, 0-based DOF of the spring, k, seed, input DOF, output DOF) of (c)
C_CASES = [("three-mass rig, spring at m2", "three_mass", 1, 150.0, 41, 0, 0),
           ("four-storey frame, spring at m4", "four_story", 3, 400.0, 42, 3, 1)]


@functools.lru_cache(maxsize=4)
def chain(example):
    """(M, C, K, forces, sensors) of a shipped chain, as nested lists (plain numpy assembly)."""
    import tomllib
    from mutext.hide import example_path, plain_chain
    with open(example_path(example), "rb") as fh:
        M, C, K, forces, sensors, _ = plain_chain(tomllib.load(fh))
    return M, C, K, forces, sensors


def grid(example):
    """The frequency grid [Hz] of a chain's sweeps: 400 points around its resonances."""
    import scipy.linalg as sla
    M, C, K, _, _ = chain(example)
    f = np.sqrt(sla.eigh(K, M, eigvals_only=True)) / (2 * np.pi)
    return np.round(frequency_grid(n=400, poles=f, margin=(2.0, 1.4), spacing="linear"), 8)


def response(M, C, K, f_hz, i_in, i_out, change=None):
    """Direct solve of one channel; ``change = (kind, dof, size)`` adds an effect at ``dof``."""
    M, C, K = (np.array(X, float) for X in (M, C, K))
    if change is not None and change[0] != "none":
        kind, dof, size = change
        {"stiffness": K, "mass": M, "damping": C}[kind][dof, dof] += size
    w = 2 * np.pi * np.asarray(f_hz, float)
    out = np.empty(w.size, complex)
    e = np.zeros(M.shape[0])
    e[i_in] = 1.0
    for k, wk in enumerate(w):
        out[k] = np.linalg.solve(K - wk ** 2 * M + 1j * wk * C, e)[i_out]
    return out


def noisy(h, seed):
    rng = np.random.default_rng(seed)
    return h + NOISE * np.abs(h) * (rng.standard_normal(h.size) + 1j * rng.standard_normal(h.size)) / math.sqrt(2)


def _lists(X):
    return [list(map(float, r)) for r in np.asarray(X, float)]


# ----------------------------------------------------------------------------
# (a)
# ----------------------------------------------------------------------------

def _a_cases():
    M, C, K, f, s = chain("three_mass")
    fz = grid("three_mass")
    h = response(M, C, K, fz, 0, 2)
    out = [("three-mass f1 -> x3, model against 1 % noise", h, noisy(h, 11)),
           ("three-mass f1 -> x3, against a stiffer rig", h, response(M, C, K, fz, 0, 2, ("stiffness", 1, 120.0)))]
    # a data set whose phase differs from the model's by nearly pi at some frequencies
    out.append(("sign-flipped data (phase differences near pi)", h, -h * np.exp(0.05j * np.sin(fz))))
    return out


def _check_a(outcomes, calls):
    score, fb = 0.0, []
    per = POINTS["a"] / len(calls)
    for call, tag, value in returned(outcomes, calls, fb):
        x = float(value)
        ref = call.ref
        if math.isfinite(x) and abs(x - ref) <= RTOL_EXACT * abs(ref):
            score += per
            continue
        msg = f"{tag} RSS: expected {fmt(ref)}, got {fmt(x)}"
        if math.isfinite(x) and abs(x - call.unwrapped) <= 1e-6 * abs(call.unwrapped):
            msg += ("; this is the difference of the logs with each phase taken on its own: take the log of "
                    "the ratio H_model / H_measured so the phase difference stays in (-pi, pi]")
        elif math.isfinite(x) and abs(x - call.mag_only) <= 1e-6 * abs(call.mag_only):
            msg += "; only the log-magnitude part: add the squared phase difference"
        elif math.isnan(x):
            msg += "; the answer is NaN"
        fb.append(msg)
    if not fb:
        fb = [f"correct: all {len(calls)} values within {RTOL_EXACT:.0e} relative"]
    return score, fb


# ----------------------------------------------------------------------------
# (b), (c)
# ----------------------------------------------------------------------------

def _check_b(outcomes, calls):
    score, fb = 0.0, []
    per = POINTS["b"] / len(calls)
    for call, tag, x in returned(outcomes, calls, fb, as_array, "response"):
        ref = call.ref
        if x.size != 2 * ref.size:
            fb.append(f"{tag} expected an array of shape (2, {ref.size}) (real and imaginary parts), "
                      f"got {x.size} numbers")
            continue
        h = x.reshape(2, -1)
        h = h[0] + 1j * h[1]
        err = float(np.max(np.abs(h - ref) / np.abs(ref)))
        if err <= RTOL_EXACT:
            score += per
            continue
        msg = f"{tag} largest relative error {fmt(err)}"
        for name, alt in call.alternatives.items():
            if np.max(np.abs(h - alt) / np.abs(alt)) <= 1e-6:
                msg += f"; this is {name}"
                break
        fb.append(msg)
    if not fb:
        fb = ["correct: both responses agree with a direct solve"]
    return score, fb


def _check_float_rel(outcomes, calls, rtol, points, what):
    score, fb = 0.0, []
    per = points / len(calls)
    for call, tag, value in returned(outcomes, calls, fb):
        x = float(value)
        if math.isfinite(x) and abs(x - call.ref) <= rtol * abs(call.ref):
            score += per
            continue
        msg = f"{tag} {what}: expected {fmt(call.ref)} within {rtol:.0%}, got {fmt(x)}"
        if math.isnan(x):
            msg += "; the answer is NaN"
        elif x > 0 and abs(x / call.ref - 1) > 0.5:
            msg += "; is the minimum of the misfit bracketed? scan the size over several decades first"
        fb.append(msg)
    if not fb:
        fb = [f"correct: within {rtol:.0%}"]
    return score, fb


# ----------------------------------------------------------------------------
# (d)
# ----------------------------------------------------------------------------

def _check_d(outcomes, calls):
    per = POINTS["d"] / len(calls)
    score, fb = 0.0, []
    for call, tag, x in returned(outcomes, calls, fb, as_array, "find_effect()"):
        x = x.ravel()
        if x.size != 3 or not np.all(np.isfinite(x)):
            fb.append(f"{tag} find_effect() must return three finite numbers [kind index, station, "
                      f"size], got {x.tolist()}")
            continue
        kind, station, size = call.key
        k_idx = int(round(x[0]))
        got_kind = KINDS[k_idx] if 0 <= k_idx < len(KINDS) else f"index {x[0]:g}"
        got_station = int(round(x[1]))
        if kind == "none":
            if got_kind == "none":
                score += per
            else:
                fb.append(f"{tag} there is no effect in these data, you found {got_kind} at mass "
                          f"{got_station}: is the improvement above 20 sigma^2/2?")
            continue
        if (got_kind, got_station) != (kind, station):
            hint = ""
            if got_kind == kind and got_station == station - 1:
                hint = "; the station is 1-based (the first mass is 1)"
            elif got_station == station:
                hint = "; the right place, another kind"
            elif got_kind == "none":
                hint = "; an effect is there: compare the misfit drop with 20 sigma^2/2 (sigma = noise)"
            fb.append(f"{tag} expected {kind} at mass {station}, got {got_kind} at mass "
                      f"{got_station}{hint}")
            continue
        score += per * 2 / 3
        if abs(x[2] - size) <= RTOL_SIZE * abs(size):
            score += per / 3
        else:
            fb.append(f"{tag} {kind} at mass {station} is right; size: expected {fmt(size)} within "
                      f"10 %, got {fmt(x[2])}")
    if not fb:
        fb = ["correct: every hidden effect found, with its size within 10 %"]
    return score, fb


def questions(rng=None):
    """The four questions; data and reference answers are made here, not in the child."""
    a_calls = []
    for label, h, d in _a_cases():
        call = Call(label, [h.real.tolist(), h.imag.tolist(), d.real.tolist(), d.imag.tolist()])
        call.ref = float(np.sum(np.abs(np.log(h / d)) ** 2))
        lm = np.log(np.abs(h / d))
        call.unwrapped = float(np.sum(lm ** 2 + (np.unwrap(np.angle(h)) - np.unwrap(np.angle(d))) ** 2))
        call.mag_only = float(np.sum(lm ** 2))
        a_calls.append(call)
    b_calls = []
    for example, dof, k in (("three_mass", 1, 200.0), ("four_story", 2, 500.0)):
        M, C, K, forces, sensors = chain(example)
        fz = grid(example)[::10]
        i, o = list(forces.values())[0], list(sensors.values())[-1]
        call = Call(f"{example}, spring {k:g} N/m at DOF {dof}", [_lists(M), _lists(C), _lists(K), fz.tolist(),
                                                                     i, o, dof, k])
        call.ref = response(M, C, K, fz, i, o, ("stiffness", dof, k))
        call.alternatives = {
            "the response without the spring": response(M, C, K, fz, i, o),
            "the response with the frequencies taken as rad/s (omega = f)":
                response(M, C, K, fz / (2 * np.pi), i, o, ("stiffness", dof, k)),
        }
        if dof + 1 < len(M):
            Kb = np.array(K, float)
            Kb[dof:dof + 2, dof:dof + 2] += k * np.array([[1, -1], [-1, 1]])
            call.alternatives["a spring between DOF dof and dof + 1, not to the ground"] = response(M, C, Kb, fz,
                                                                                                     i, o)
        b_calls.append(call)
    c_calls = []
    for label, example, dof, k, seed, i, o in C_CASES:
        M, C, K, _, _ = chain(example)
        fz = grid(example)
        d = noisy(response(M, C, K, fz, i, o, ("stiffness", dof, k)), seed)
        call = Call(label, [_lists(M), _lists(C), _lists(K), fz.tolist(), i, o, d.real.tolist(), d.imag.tolist(),
                            dof])
        call.ref = k
        c_calls.append(call)
    d_calls = []
    for label, example, kind, station, size, seed in D_CASES:
        M, C, K, forces, sensors = chain(example)
        fz = grid(example)
        i = list(forces.values())[0]
        chans = [[i, o] for o in sensors.values()]
        data = [noisy(response(M, C, K, fz, a, b, (kind, station - 1, size)), seed + 7 * n)
                for n, (a, b) in enumerate(chans)]
        call = Call(label, [_lists(M), _lists(C), _lists(K), fz.tolist(), chans, [d.real.tolist() for d in data],
                            [d.imag.tolist() for d in data], NOISE])
        call.key = (kind, station, size)
        d_calls.append(call)
    return [
        Question("a", "log_misfit", "RSS of the complex log ratio", POINTS["a"], "float", a_calls,
                 lambda oc: _check_a(oc, a_calls)),
        Question("b", "response_with_grounded_spring", "response with an added grounded spring", POINTS["b"],
                 "array", b_calls, lambda oc: _check_b(oc, b_calls)),
        Question("c", "fit_grounded_spring", "size of a hidden grounded spring", POINTS["c"], "float", c_calls,
                 lambda oc: _check_float_rel(oc, c_calls, RTOL_FIT, POINTS["c"], "k (N/m)")),
        Question("d", "find_effect", "kind, place and size of a hidden effect", POINTS["d"], "array", d_calls,
                 lambda oc: _check_d(oc, d_calls)),
    ]


EXERCISE = Exercise("ex05_diagnose", "Diagnosis: find the effect hidden in measured frequency responses",
                    questions, stub="exercises/ex05_diagnose.py",
                    blocked_modules=("mutext.diagnose", "mutext.hide", "mutext.rotor", "mutext.mbi",
                                     "mutext.report", "mutext.commands"))
