r"""Grader of exercise ``ex05_diagnose``: find the effect hidden in measured FRFs (book: diagnosis chapter).

Questions (10 points):

(a) ``log_misfit``, 1.5 points: the RSS of the complex log ratio on three
    channel pairs (relative tolerance 1e-6): a model against its noisy data,
    against a changed rig, and against data whose phase differs from the
    model's by nearly pi (where the difference of the logs of unwrapped
    phases goes wrong).
(b) ``response_with_grounded_spring``, 2 points: the response with an added
    grounded spring on both chains (1e-6 relative, as a direct solve gives).
(c) ``fit_grounded_spring``, 2 points: the stiffness of a hidden grounded
    spring from one noisy channel (one case per chain, 2 %).
(d) ``find_effect``, 4.5 points: four hidden cases on the three-mass rig or
    the four-storey frame, 1 % noise, each a grounded spring, an added mass,
    a grounded damper or none; how many are "none" (0, 1 or 2) is drawn too.

Inputs are drawn from the generator the grader is given (:mod:`mutext_grader.core`):
the chain, channels, place, size and noise of every case, the kind of each
hidden effect and the number of "none" cases of (d).  Sizes are drawn within
ranges like the book's examples (a spring or a mass of 5-30 % of the
station's own, a damper of 2-10 % of its critical scale) and a draw is kept
only when the data determine the size far more tightly than the tolerance
(:func:`size_spread`, from the Fisher information of the complex log ratio:
at most 0.3 % for (d), 0.2 % for (c), against 10 % and 2 %) and the effect
changes the data by far more than the noise (:func:`effect_strength`).

Scoring of (d), 1.125 points a case: 0.75 when the kind AND the station are
both right, 0.375 more for the size within 10 %.  A "none" case scores its
1.125 only if the submission also found at least one hidden effect (kind and
station right) in another case of the run, so answering "none" everywhere
scores 0, and a constant kind and station earns only the rare case it
happens to match.

Feedback never prints a hidden parameter or a reference value: calls are
"case n of N", and a wrong answer is described by what is right and what is
not ("the kind is right, the station is not", "the size is off by more than
10 %").  It names the usual mistakes: Hz taken for rad/s, the phase wrapped
wrongly, a spring added between two masses instead of to the ground, the
station given 0-based.

The chains are the shipped model files read by :func:`mutext.hide.plain_chain`
(plain numpy, no finite-element code); the data are made here, in the
grading process.
"""
from __future__ import annotations

import functools
import math

import numpy as np

from mutext.response import frequency_grid
from .compare import as_array, returned
from .core import Call, Exercise, Question

POINTS = {"a": 1.5, "b": 2.0, "c": 2.0, "d": 4.5}
KINDS = ("none", "stiffness", "mass", "damping")
RTOL_EXACT = 1e-6
RTOL_FIT = 0.02
RTOL_SIZE = 0.10
NOISE = 0.01
EXAMPLES = ("three_mass", "four_story")

#: cases of (d), and how many of them may be "none"
N_D = 4
MAX_NONE = 2
#: relative size of a drawn effect: (low, high) times the station's own mass or stiffness, or for a damper
#: times sqrt(k m) of the station (log-uniform)
SIZE_RANGE = {"stiffness": (0.05, 0.30), "mass": (0.05, 0.30), "damping": (0.02, 0.10)}
#: (low, high) times the station's stiffness of the hidden spring of (c) and the added spring of (b)
C_RANGE = (0.05, 0.50)
B_RANGE = (0.10, 1.50)
#: a draw is kept when the size's standard deviation from the data (relative) is below this ...
MAX_SPREAD_D = 0.003
MAX_SPREAD_C = 0.002
#: ... and the effect changes the data by this many times the noise's RSS expectation N sigma^2 at least
MIN_STRENGTH = 50.0


@functools.lru_cache(maxsize=4)
def chain(example):
    """(M, C, K, forces, sensors) of a shipped chain, as nested lists (plain numpy assembly)."""
    import tomllib
    from mutext.hide import example_path, plain_chain
    with open(example_path(example), "rb") as fh:
        M, C, K, forces, sensors, _ = plain_chain(tomllib.load(fh))
    return M, C, K, forces, sensors


@functools.lru_cache(maxsize=4)
def _grid(example):
    import scipy.linalg as sla
    M, C, K, _, _ = chain(example)
    f = np.sqrt(sla.eigh(K, M, eigvals_only=True)) / (2 * np.pi)
    return np.round(frequency_grid(n=400, poles=f, margin=(2.0, 1.4), spacing="linear"), 8)


def grid(example):
    """The frequency grid [Hz] of a chain's sweeps: 400 points around its resonances."""
    return _grid(example).copy()


def response(M, C, K, f_hz, i_in, i_out, change=None):
    """Direct solve of one channel; ``change = (kind, dof, size)`` adds an effect at ``dof``."""
    M, C, K = (np.array(X, float) for X in (M, C, K))
    if change is not None and change[0] != "none":
        kind, dof, size = change
        {"stiffness": K, "mass": M, "damping": C}[kind][dof, dof] += size
    w = 2 * np.pi * np.asarray(f_hz, float)
    Z = K[None] - (w ** 2)[:, None, None] * M[None] + 1j * w[:, None, None] * C[None]
    e = np.zeros((w.size, M.shape[0]))
    e[:, i_in] = 1.0
    return np.linalg.solve(Z, e[..., None])[:, i_out, 0]


def noisy(h, seed):
    """``h`` with 1 % relative circular complex Gaussian noise from the generator seeded ``seed``."""
    rng = np.random.default_rng(seed)
    return h + NOISE * np.abs(h) * (rng.standard_normal(h.size) + 1j * rng.standard_normal(h.size)) / math.sqrt(2)


def size_spread(example, kind, dof, size, channels):
    """The relative standard deviation of a fitted size from the data of ``channels`` at 1 % noise.

    One real parameter fitted to complex log ratios of variance sigma^2 (sigma^2/2 each part):
    var(size)/size^2 = sigma^2 / (2 sum |d ln H / d ln size|^2)."""
    M, C, K, _, _ = chain(example)
    f = grid(example)
    s2 = 0.0
    for i, o in channels:
        h1 = response(M, C, K, f, i, o, (kind, dof, size))
        h2 = response(M, C, K, f, i, o, (kind, dof, size * 1.0001))
        s2 += float(np.sum(np.abs(np.log(h2 / h1) / math.log(1.0001)) ** 2))
    return NOISE / math.sqrt(2 * s2)


def effect_strength(example, kind, dof, size, channels):
    """How far the effect moves the data: its RSS against the model over the noise's, N sigma^2."""
    M, C, K, _, _ = chain(example)
    f = grid(example)
    rss = sum(float(np.sum(np.abs(np.log(response(M, C, K, f, i, o, (kind, dof, size))
                                          / response(M, C, K, f, i, o))) ** 2)) for i, o in channels)
    return rss / (len(channels) * f.size * NOISE ** 2)


def _scale(example, kind, dof):
    M, C, K, _, _ = chain(example)
    m, k = float(M[dof][dof]), float(K[dof][dof])
    return {"stiffness": k, "mass": m, "damping": math.sqrt(k * m)}[kind]


def _seed(rng):
    return int(rng.integers(2 ** 62))


def _lists(X):
    return [list(map(float, r)) for r in np.asarray(X, float)]


def draw_effect(rng, example, channels, kinds=KINDS[1:], dofs=None, ranges=SIZE_RANGE, max_spread=MAX_SPREAD_D):
    """``(kind, dof, size)`` of a hidden effect on ``example`` that the data of ``channels`` determine well."""
    n = len(chain(example)[0])
    for _ in range(200):
        kind = kinds[int(rng.integers(len(kinds)))]
        dof = int(rng.integers(n)) if dofs is None else int(dofs[int(rng.integers(len(dofs)))])
        lo, hi = ranges[kind]
        size = _scale(example, kind, dof) * float(np.exp(rng.uniform(math.log(lo), math.log(hi))))
        size = float(f"{size:.4g}")
        if size_spread(example, kind, dof, size, channels) <= max_spread \
                and effect_strength(example, kind, dof, size, channels) >= MIN_STRENGTH:
            return kind, dof, size
    raise RuntimeError(f"no well-determined effect drawn on {example}")   # pragma: no cover


def d_channels(example):
    """The channels of (d): the first force to every sensor (0-based DOFs)."""
    _, _, _, forces, sensors = chain(example)
    i = list(forces.values())[0]
    return [(i, o) for o in sensors.values()]


def d_cases(rng):
    """The hidden cases of (d): ``(example, kind, 1-based station, size, noise seed)``."""
    n_none = int(rng.integers(MAX_NONE + 1))
    nones = set(rng.choice(N_D, size=n_none, replace=False).tolist())
    out = []
    for n in range(N_D):
        example = EXAMPLES[int(rng.integers(len(EXAMPLES)))]
        if n in nones:
            out.append((example, "none", 0, 0.0, _seed(rng)))
            continue
        kind, dof, size = draw_effect(rng, example, d_channels(example))
        out.append((example, kind, dof + 1, size, _seed(rng)))
    return out


# ----------------------------------------------------------------------------
# (a)
# ----------------------------------------------------------------------------

def _a_cases(rng):
    """(h, d) of the three pairs: noisy data, a changed rig, data of nearly the opposite phase."""
    out = []
    for n in range(3):
        example = EXAMPLES[int(rng.integers(len(EXAMPLES)))]
        M, C, K, forces, sensors = chain(example)
        fz = grid(example)
        i = list(forces.values())[int(rng.integers(len(forces)))]
        o = list(sensors.values())[int(rng.integers(len(sensors)))]
        h = response(M, C, K, fz, i, o)
        if n == 0:
            d = noisy(h, _seed(rng))
        elif n == 1:
            kind, dof, size = draw_effect(rng, example, [(i, o)], max_spread=1.0)
            d = response(M, C, K, fz, i, o, (kind, dof, size))
        else:
            # the phase of the data differs from the model's by pi minus a small angle that changes sign
            amp = rng.uniform(0.03, 0.1)
            cycles = rng.uniform(1.5, 4.0)
            phase = rng.uniform(0, 2 * np.pi)
            x = (fz - fz[0]) / (fz[-1] - fz[0])
            d = -h * np.exp(1j * amp * np.sin(2 * np.pi * cycles * x + phase))
        out.append((h, d))
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
        msg = f"{tag} the RSS is not within {RTOL_EXACT:.0e} relative of the reference"
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
            fb.append(f"{tag} expected an array of shape (2, {ref.size}) (real and imaginary parts, one column "
                      f"per frequency), got {x.size} numbers")
            continue
        h = x.reshape(2, -1)
        h = h[0] + 1j * h[1]
        with np.errstate(all="ignore"):
            err = float(np.max(np.abs(h - ref) / np.abs(ref)))
        if err <= RTOL_EXACT:
            score += per
            continue
        msg = f"{tag} the response is not within {RTOL_EXACT:.0e} relative of a direct solve"
        for name, alt in call.alternatives.items():
            with np.errstate(all="ignore"):
                if np.max(np.abs(h - alt) / np.abs(alt)) <= 1e-6:
                    msg += f"; this is {name}"
                    break
        else:
            if not math.isfinite(err):
                msg += "; it holds NaN or infinite values"
        fb.append(msg)
    if not fb:
        fb = ["correct: both responses agree with a direct solve"]
    return score, fb


def _check_c(outcomes, calls):
    score, fb = 0.0, []
    per = POINTS["c"] / len(calls)
    for call, tag, value in returned(outcomes, calls, fb):
        x = float(value)
        if math.isfinite(x) and abs(x - call.ref) <= RTOL_FIT * abs(call.ref):
            score += per
            continue
        msg = f"{tag} k is not within {RTOL_FIT:.0%} of the hidden spring's"
        if math.isnan(x):
            msg += "; the answer is NaN"
        elif not x > 0:
            msg += "; a spring's stiffness is positive"
        elif abs(x / call.ref - 1) > 0.5:
            msg += "; is the minimum of the misfit bracketed? scan the size over several decades first"
        fb.append(msg)
    if not fb:
        fb = [f"correct: within {RTOL_FIT:.0%}"]
    return score, fb


# ----------------------------------------------------------------------------
# (d)
# ----------------------------------------------------------------------------

def _check_d(outcomes, calls):
    """Per case: kind and station, then size; "none" cases only count with a hidden effect found."""
    per = POINTS["d"] / len(calls)
    fb, found_effect, none_right, off_by_one, zero_station, any_none = [], 0, 0, 0, False, False
    score = 0.0
    for call, tag, x in returned(outcomes, calls, fb, as_array, "find_effect()"):
        x = x.ravel()
        if x.size != 3 or not np.all(np.isfinite(x)):
            fb.append(f"{tag} find_effect() must return three finite numbers [kind index, station, "
                      f"size], got {x.size} numbers" + ("" if x.size != 3 else " (not all finite)"))
            continue
        kind, station, size = call.key
        k_idx = int(round(x[0]))
        if abs(x[0] - k_idx) > 1e-9 or not 0 <= k_idx < len(KINDS):
            fb.append(f"{tag} the kind must be an index in KINDS (0, 1, 2 or 3), got {x[0]:g}")
            continue
        got_kind = KINDS[k_idx]
        got_station = int(round(x[1]))
        if got_kind != "none" and got_station == 0:
            zero_station = True
        any_none = any_none or got_kind == "none"
        if kind == "none":
            if got_kind == "none":
                none_right += 1
            else:
                fb.append(f"{tag} the kind is not right: is the misfit drop of the best hypothesis above "
                          "20 sigma^2/2 (below it the answer is none)?")
            continue
        if got_kind == "none":
            fb.append(f"{tag} the kind is not right: compare the misfit drop of the best hypothesis with "
                      "20 sigma^2/2 (sigma = noise)")
            continue
        if got_kind != kind or got_station != station:
            if got_station == station - 1:
                off_by_one += 1
            if got_kind == kind:
                fb.append(f"{tag} the kind is right, the station is not")
            elif got_station == station:
                fb.append(f"{tag} the station is right, the kind is not")
            else:
                fb.append(f"{tag} neither the kind nor the station is right")
            continue
        found_effect += 1
        score += per * 2 / 3
        if abs(x[2] - size) <= RTOL_SIZE * abs(size):
            score += per / 3
        else:
            fb.append(f"{tag} the kind and the station are right; the size is off by more than "
                      f"{RTOL_SIZE:.0%}")
    if found_effect:
        score += none_right * per
    elif any_none:
        fb.append("'none' answers score only when at least one hidden effect (kind and station) is found in "
                  "another case")
    if zero_station or off_by_one >= 2:
        fb.append("the stations are 1-based (the first mass is 1)")
    if not fb:
        fb = ["correct: every hidden effect found, with its size within 10 %"]
    return score, fb


def questions(rng=None):
    """The four questions, drawn from ``rng``; data and reference answers are made here, not in the child."""
    rng = np.random.default_rng() if rng is None else rng
    a_pairs = _a_cases(rng)
    a_calls = []
    for n, (h, d) in enumerate(a_pairs):
        call = Call(f"case {n + 1} of {len(a_pairs)}", [h.real.tolist(), h.imag.tolist(), d.real.tolist(),
                                                        d.imag.tolist()])
        call.ref = float(np.sum(np.abs(np.log(h / d)) ** 2))
        lm = np.log(np.abs(h / d))
        call.unwrapped = float(np.sum(lm ** 2 + (np.unwrap(np.angle(h)) - np.unwrap(np.angle(d))) ** 2))
        call.mag_only = float(np.sum(lm ** 2))
        a_calls.append(call)
    b_calls = []
    order = list(EXAMPLES) if rng.random() < 0.5 else list(EXAMPLES)[::-1]
    for n, example in enumerate(order):
        M, C, K, forces, sensors = chain(example)
        dof = int(rng.integers(len(M) - 1))          # a neighbour above: the between-masses mistake is named
        k = float(f"{float(K[dof][dof]) * np.exp(rng.uniform(*np.log(B_RANGE))):.4g}")
        i = list(forces.values())[int(rng.integers(len(forces)))]
        o = list(sensors.values())[int(rng.integers(len(sensors)))]
        fz = grid(example)[int(rng.integers(10))::10]
        call = Call(f"case {n + 1} of 2 ({example.replace('_', '-')} chain)",
                    [_lists(M), _lists(C), _lists(K), fz.tolist(), i, o, dof, k])
        call.ref = response(M, C, K, fz, i, o, ("stiffness", dof, k))
        Kb = np.array(K, float)
        Kb[dof:dof + 2, dof:dof + 2] += k * np.array([[1, -1], [-1, 1]])
        call.alternatives = {
            "the response without the spring": response(M, C, K, fz, i, o),
            "the response with the frequencies taken as rad/s (omega = f)":
                response(M, C, K, fz / (2 * np.pi), i, o, ("stiffness", dof, k)),
            "a spring between DOF dof and dof + 1, not to the ground": response(M, C, Kb, fz, i, o),
        }
        b_calls.append(call)
    c_calls = []
    order = list(EXAMPLES) if rng.random() < 0.5 else list(EXAMPLES)[::-1]
    for n, example in enumerate(order):
        M, C, K, forces, sensors = chain(example)
        i = list(forces.values())[int(rng.integers(len(forces)))]
        o = list(sensors.values())[int(rng.integers(len(sensors)))]
        _, dof, k = draw_effect(rng, example, [(i, o)], kinds=("stiffness",), ranges={"stiffness": C_RANGE},
                                max_spread=MAX_SPREAD_C)
        fz = grid(example)
        d = noisy(response(M, C, K, fz, i, o, ("stiffness", dof, k)), _seed(rng))
        call = Call(f"case {n + 1} of 2 ({example.replace('_', '-')} chain)",
                    [_lists(M), _lists(C), _lists(K), fz.tolist(), i, o, d.real.tolist(), d.imag.tolist(), dof])
        call.ref = k
        c_calls.append(call)
    d_calls = []
    cases = d_cases(rng)
    for n, (example, kind, station, size, seed) in enumerate(cases):
        M, C, K, _, _ = chain(example)
        fz = grid(example)
        chans = d_channels(example)
        noise = np.random.default_rng(seed)
        data = [noisy(response(M, C, K, fz, a, b, (kind, station - 1, size)), _seed(noise)) for a, b in chans]
        call = Call(f"case {n + 1} of {len(cases)} ({example.replace('_', '-')} chain)",
                    [_lists(M), _lists(C), _lists(K), fz.tolist(), [list(c) for c in chans],
                     [d.real.tolist() for d in data], [d.imag.tolist() for d in data], NOISE])
        call.key = (kind, station, size)
        d_calls.append(call)
    return [
        Question("a", "log_misfit", "RSS of the complex log ratio", POINTS["a"], "float", a_calls,
                 lambda oc: _check_a(oc, a_calls)),
        Question("b", "response_with_grounded_spring", "response with an added grounded spring", POINTS["b"],
                 "array", b_calls, lambda oc: _check_b(oc, b_calls)),
        Question("c", "fit_grounded_spring", "size of a hidden grounded spring", POINTS["c"], "float", c_calls,
                 lambda oc: _check_c(oc, c_calls)),
        Question("d", "find_effect", "kind, place and size of a hidden effect", POINTS["d"], "array", d_calls,
                 lambda oc: _check_d(oc, d_calls)),
    ]


EXERCISE = Exercise("ex05_diagnose", "Diagnosis: find the effect hidden in measured frequency responses",
                    questions, stub="exercises/ex05_diagnose.py",
                    blocked_modules=("mutext.diagnose", "mutext.hide", "mutext.rotor", "mutext.mbi",
                                     "mutext.report", "mutext.commands"))
