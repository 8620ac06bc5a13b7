"""Grader of exercise ``ex01_two_mass_hinf``: H-infinity control of the two-mass system.

Questions (10 points):

(a) ``mechanical_model(m1, m2, k1, k2)``, 2 points: compared channel by
    channel through frequency responses at two parameter sets.
(b) ``generalized_plant(**params)``, 3 points: the 9 channels of the
    generalized plant, called with no arguments (the defaults), with the
    mechanical parameters only and with all eight.  A channel counts when it
    is right in every call; the 6 channels that carry a signal share the
    points, and each of the 3 channels that must be zero but is not takes one
    share away.
(c) ``hinf_norm(sys)``, 2 points: five stable systems, relative tolerance 1e-4.
(d) ``controller()``, 3 points: the closed loop is rebuilt here with the
    reference plant; 1 point for stability, 2 more if the closed-loop norm is
    within 2 % of the optimal level (1 more if within 10 %).

Inputs are drawn per run from the generator the grader passes
(:func:`_draw`): the masses and stiffnesses 30 % around the thesis's and a
second set's, the weights 10-40 % away from the defaults (so a weight or a
scaling hard-coded to the default is seen), and the five systems of (c) of
the same kinds as before (a low-pass with its peak at DC, a resonance with
damping ratio about 0.001, a peak at infinite frequency, a random 2x2 MIMO
system with 4 states, a damped two-mass model).  (d) has no inputs: the
question names the thesis plant.  Labels name a case by its number and
kind only; feedback names the student's own values and the mistake, never a
reference value or a drawn parameter.

What earns nothing (the answers that do not solve the question):

* (a), (b): a zero model, a model that ignores its arguments (a table of
  the thesis plant: its channels are wrong in the calls with other
  arguments, and a channel counts only when right in every call), the
  structurally zero channels of (b) alone;
* (c): a function seen returning a known shortcut (the gain at DC, at
  infinite frequency, the square of the norm) where it is wrong earns
  nothing on the systems whose norm a shortcut happens to give (the peak at
  DC, the peak at infinite frequency);
* (d): a controller that does not stabilise the reference plant (a zero or
  static controller leaves its undamped modes on the imaginary axis), one
  whose closed loop has an infinite norm, or whose computed norm is beaten
  by its own frequency response sampled at the plant's natural frequencies
  and at its poles (a realisation so ill-conditioned that rounding would
  pass an undamped mode as stable).

Every returned model is checked for size in the check function before
anything is built or computed: at most :data:`MAX_STATES_FACTOR` times the
reference model's states (a model or controller padded to hundreds of
states scores 0 with a message and is never computed).

Partial credit is otherwise proportional to the channels or systems that are right.
"""
from __future__ import annotations

import functools
import threading

import numpy as np

from mutext.lti import hinf_norm as ref_hinf_norm
from mutext.lti import lft_lower, mck_to_ss, ss
from .compare import build_ss, compare_responses, fmt, matches, permutation_hint, resonance_safe_grid, response
from .core import Call, Exercise, Question
from .solutions import ex01_two_mass_hinf as sol

POINTS = {"a": 2.0, "b": 3.0, "c": 2.0, "d": 3.0}
RTOL_MODEL = 1e-4      # frequency responses: different state coordinates only change rounding
RTOL_NORM = 1e-4
CONTROLLER_FULL = 1.02     # closed-loop norm / optimal level for full marks
CONTROLLER_PARTIAL = 1.10
MAX_STATES_FACTOR = 3      # a returned model may have at most this many times the reference's states
MODEL_STATES = 4           # states of the two-mass model, of the generalized plant and of the thesis controller

DEFAULTS = dict(m1=1.0, m2=2.0, k1=450.0, k2=175.0, f_max=10.0, eta_max=1e-4, x_max=0.035, u_max=50.0)
OTHER = dict(m1=1.5, m2=0.5, k1=300.0, k2=80.0, f_max=4.0, eta_max=2e-4, x_max=0.02, u_max=80.0)
MECH = ["m1", "m2", "k1", "k2"]
WEIGHTS = ["f_max", "eta_max", "x_max", "u_max"]


# ----------------------------------------------------------------------------
# inputs drawn per run
# ----------------------------------------------------------------------------

def _around(rng, x, rel=0.3):
    """``x`` times a factor drawn in ``[1 - rel, 1 + rel]``."""
    return float(x * rng.uniform(1.0 - rel, 1.0 + rel))


def _away(rng, x):
    """``x`` times a factor in ``[0.6, 0.9]`` or ``[1.1, 1.4]``: never the default itself."""
    f = rng.uniform(0.6, 0.9) if rng.random() < 0.5 else rng.uniform(1.1, 1.4)
    return float(x * f)


def _stable_random(rng, n):
    A = rng.standard_normal((n, n))
    return A - (np.linalg.eigvals(A).real.max() + rng.uniform(0.2, 0.5)) * np.eye(n)


def _draw(rng):
    """Every graded input of one run, drawn from ``rng`` (``questions`` and ``prepare`` both call this)."""
    d = {}
    d["mech"] = [{k: _around(rng, base[k]) for k in MECH} for base in (DEFAULTS, OTHER)]
    d["plant"] = [{},
                  {k: _away(rng, DEFAULTS[k]) for k in MECH},
                  {**{k: _around(rng, OTHER[k]) for k in MECH}, **{k: _away(rng, DEFAULTS[k]) for k in WEIGHTS}}]
    systems = []
    a, g = rng.uniform(0.5, 3.0), rng.uniform(1.0, 4.0)
    systems.append(("first-order low-pass, peak at DC", ss([[-a]], [[1.0]], [[g]], [[0.0]])))
    wn, z = rng.uniform(6.0, 16.0), 1e-3 * rng.uniform(0.7, 1.4)
    systems.append(("lightly damped resonance (damping ratio about 0.001)",
                    ss([[0.0, 1.0], [-wn * wn, -2 * z * wn]], [[0.0], [wn * wn]], [[1.0, 0.0]], [[0.0]])))
    a = rng.uniform(0.5, 3.0)
    b, dd = a * rng.uniform(0.05, 0.3), rng.uniform(0.5, 2.0)
    systems.append(("a lead-lag whose peak is at infinite frequency (the D matrix)",
                    ss([[-a]], [[1.0]], [[dd * (b - a)]], [[dd]])))
    systems.append(("random 2x2 MIMO system with 4 states and D != 0",
                    ss(_stable_random(rng, 4), rng.standard_normal((4, 2)), rng.standard_normal((2, 4)),
                       0.3 * rng.standard_normal((2, 2)))))
    p = {k: _around(rng, DEFAULTS[k]) for k in MECH}
    M = np.diag([p["m1"], p["m2"]])
    K = np.array([[p["k1"], -p["k1"]], [-p["k1"], p["k1"] + p["k2"]]])
    systems.append(("damped two-mass model [f_e, u] -> [x1, x2] (damping 0.02 K)",
                    mck_to_ss(M, 0.02 * K, K, {"f_e": 0, "u": 1}, {"x1": 0, "x2": 1})))
    d["systems"] = systems
    return d


def _raw_dims(value):
    """Upper bounds of (states, inputs, outputs) read off the returned lists, before any matrix is built."""
    A, B, C, D = (value.get(k) or [] for k in "ABCD")
    n = max(len(A), max((len(r) for r in A), default=0), len(B), max((len(r) for r in C), default=0))
    m = max(max((len(r) for r in B), default=0), max((len(r) for r in D), default=0))
    p = max(len(C), len(D))
    return n, m, p


def _too_large(value, what, ref_states=MODEL_STATES, max_io=3):
    """A message if the returned model is larger than the grader computes with (else None)."""
    if not isinstance(value, dict):
        return None
    n, m, p = _raw_dims(value)
    cap = MAX_STATES_FACTOR * ref_states
    if n > cap:
        return (f"{what}: the model has {n} states; at most {cap} are accepted ({MAX_STATES_FACTOR} times the "
                f"{ref_states} of a minimal model): not evaluated, 0 points")
    if m > 10 * max_io or p > 10 * max_io:
        return f"{what}: the model has {m} inputs and {p} outputs: not evaluated, 0 points"
    return None


def _sized(outcomes, calls, what, ref_states=MODEL_STATES):
    """The outcomes with oversized models replaced by an error before anything is computed."""
    out = []
    for oc in outcomes:
        err = _too_large(oc.get("value"), what, ref_states) if oc.get("ok") else None
        out.append({"ok": False, "error": err} if err else oc)
    return out


def _band(got, exp):
    """How far ``got`` is from ``exp``, in words that do not give ``exp`` away."""
    r = abs(got / exp - 1.0) if exp else np.inf
    if r < 1e-2:
        return "by less than 1 %"
    if r < 0.1:
        return "by 1-10 %"
    return "by more than 10 %"


def _describe(gs, gr, w, label, atol, hints):
    """A mismatching channel in words that name the student's values and the mistake, not the reference's."""
    if not np.all(np.isfinite(gs)):
        return f"channel {label}: the response is not finite at some test frequencies"
    if np.all(np.abs(gr) <= atol):
        return f"channel {label} should be zero, got a response of magnitude {np.abs(gs).max():.3g}"
    if np.all(np.abs(gs) <= atol):
        return f"channel {label} is missing: your model gives 0"
    nz = np.abs(gr) > atol
    r = gs[nz] / gr[nz]
    if r.size and np.all(np.abs(r - r[0]) <= 1e-4 * abs(r[0])):
        factor = r[0].real if abs(r[0].imag) <= 1e-6 * abs(r[0]) else r[0]
        for f, text in hints:
            if np.isreal(factor) and abs(factor - f) <= 1e-4 * abs(f):
                return f"channel {label} is off by a constant factor: {text}"
        if np.isreal(factor) and factor < 0:
            return f"channel {label} has the opposite sign and a different size"
        return f"channel {label} is off by a constant factor (a weight, a scaling or a sign)"
    bad = int(np.sum(np.abs(gs - gr) > RTOL_MODEL * np.abs(gr) + atol))
    return f"channel {label} has different dynamics (it differs at {bad} of the {len(w)} test frequencies)"


def _channels(Gs, Gr, w, ins, outs, hints=None):
    """``(ok, message)`` per channel, in the order output-major (as :func:`compare_responses`)."""
    atol = 1e-9 * max(np.abs(Gr).max(), 1e-300)
    checks = compare_responses(Gs, Gr, w, ins, outs, rtol=RTOL_MODEL, atol=atol)
    out = []
    for k, c in enumerate(checks):
        i, j = divmod(k, Gr.shape[1])
        msg = "" if c.ok else _describe(Gs[i, j], Gr[i, j], w, f"{c.inp} -> {c.out}", atol,
                                        hints(i, j) if hints else [])
        out.append((c.ok, msg))
    return out


def _parsed(outcomes, calls, feedback, what):
    """``(index, call, tag, StateSpace)`` of the calls that returned a model."""
    for i, (call, oc) in enumerate(zip(calls, outcomes)):
        tag = f"[{call.label}]"
        if not oc["ok"]:
            feedback.append(f"{tag} {oc['error']}")
            continue
        S, err = build_ss(oc["value"], what)
        if err:
            feedback.append(f"{tag} {err}")
            continue
        yield i, call, tag, S


# ----------------------------------------------------------------------------
# (a) mechanical model
# ----------------------------------------------------------------------------

def _mech_alternatives(m1, m2, k1, k2):
    """Models that result from common mistakes, with the explanation."""
    Z, I = np.zeros((2, 2)), np.eye(2)
    M = np.diag([m1, m2])
    K_swapped = np.array([[k1 + k2, -k1], [-k1, k1]])
    unscaled = ss(np.block([[Z, I], [-np.linalg.solve(M, [[k1, -k1], [-k1, k1 + k2]]), Z]]),
                  np.vstack([Z, I]), np.hstack([I, Z]), Z)
    return [
        (sol.mechanical_model(m2, m1, k1, k2), "it matches the model with m1 and m2 swapped"),
        (sol.mechanical_model(m1, m2, k2, k1), "it matches the model with k1 and k2 swapped"),
        (mck_to_ss(M, None, K_swapped, {"f_e": 0, "u": 1}, {"x1": 0, "x2": 1}),
         "it matches a model with k2 attached to m1; k2 holds m2 to the ground"),
        (unscaled, "it matches B = [0; I]: the forces must be divided by the masses (B = [0; M^-1])"),
    ]


def _check_mechanical(outcomes, calls):
    ins, outs = ["f_e", "u"], ["x1", "x2"]
    n_ok, n_all = 0, 4 * len(calls)
    fb = []
    outcomes = _sized(outcomes, calls, "mechanical_model()")
    for _, call, tag, S in _parsed(outcomes, calls, fb, "mechanical_model()"):
        p = dict(zip(MECH, call.args))
        ref = sol.mechanical_model(**p)
        if (S.ninputs, S.noutputs) != (2, 2):
            fb.append(f"{tag} expected 2 inputs [f_e, u] and 2 outputs [x1, x2], got {S.ninputs} inputs "
                      f"and {S.noutputs} outputs")
            continue
        w = resonance_safe_grid(ref)
        Gr = response(ref, w)[0]
        Gs, err = response(S, w)
        if err:
            fb.append(f"{tag} {err}")
            continue
        checks = _channels(Gs, Gr, w, ins, outs)
        n_ok += sum(ok for ok, _ in checks)
        if all(ok for ok, _ in checks):
            continue
        atol = 1e-9 * np.abs(Gr).max()
        hint = permutation_hint(Gs, Gr, ins, outs, RTOL_MODEL)
        for alt, text in _mech_alternatives(**p):
            if hint is None and matches(Gs, response(alt, w)[0], RTOL_MODEL, atol):
                hint = text
        fb += [f"{tag} {msg}" for ok, msg in checks if not ok]
        if hint:
            fb.append(f"{tag} hint: {hint}")
    if n_ok == n_all:
        fb.insert(0, "correct: all channels match at both parameter sets")
    return POINTS["a"] * n_ok / n_all, fb


# ----------------------------------------------------------------------------
# (b) generalized plant
# ----------------------------------------------------------------------------

PLANT_INPUTS = ["f1", "f2", "u"]
PLANT_OUTPUTS = ["z1", "z2", "y"]
CHANNEL_ROLE = {
    ("f1", "z1"): "disturbance to weighted x1", ("f2", "z1"): "noise must not reach x1",
    ("u", "z1"): "control force to weighted x1", ("f1", "z2"): "must be zero",
    ("f2", "z2"): "must be zero", ("u", "z2"): "control weight",
    ("f1", "y"): "disturbance to measurement", ("f2", "y"): "sensor noise", ("u", "y"): "control force to measurement",
}
ZERO_CHANNELS = {("f2", "z1"), ("f1", "z2"), ("f2", "z2")}


def _plant_hints(p):
    """(out, in) -> list of (factor, explanation) for constant-factor errors (no numbers in the texts)."""
    d = DEFAULTS
    rows = {
        0: [(p["x_max"] ** 2, "the z1 weight looks like x_max instead of 1/x_max"),
            (p["x_max"], "z1 looks unweighted: x1 must be divided by x_max"),
            (28.6 * p["x_max"], "the z1 weight looks like the thesis's rounded 28.6 instead of 1/x_max"),
            (p["x_max"] / d["x_max"], "the z1 weight looks hard-coded to the default 1/x_max instead of using "
                                      "the argument x_max"),
            (-1.0, "the sign of z1 is flipped")],
        1: [(p["u_max"] ** 2, "the z2 weight looks like u_max instead of 1/u_max"),
            (p["u_max"], "z2 looks unweighted: u must be divided by u_max"),
            (p["u_max"] / d["u_max"], "the z2 weight looks hard-coded to the default 1/u_max instead of using "
                                      "the argument u_max"),
            (-1.0, "the sign of z2 is flipped")],
        2: [(-1.0, "the sign of y is flipped")],
    }
    cols = {
        0: [(1 / p["f_max"], "f1 is not scaled: the force on m1 is f_max*f1"),
            (p["f_max"] ** -2, "f1 looks scaled by 1/f_max instead of f_max"),
            (d["f_max"] / p["f_max"], "f_max looks hard-coded to the default instead of the argument")],
        1: [(1 / p["eta_max"], "f2 is not scaled: the noise is eta_max*f2"),
            (p["eta_max"] ** -2, "f2 looks scaled by 1/eta_max instead of eta_max"),
            (d["eta_max"] / p["eta_max"], "eta_max looks hard-coded to the default instead of the argument")],
        2: [(-1.0, "the sign of u is flipped")],
    }

    def hints(i, j):
        # a factor that is exactly 1 explains nothing (happens for the defaults)
        return [(f, t) for f, t in rows[i] + cols[j] if abs(f - 1.0) > 1e-9]
    return hints


def _check_plant(outcomes, calls):
    names = [(i, o) for o in PLANT_OUTPUTS for i in PLANT_INPUTS]    # output-major, as _channels
    right = {c: True for c in names}
    fb = []
    outcomes = _sized(outcomes, calls, "generalized_plant()")
    usable = set()
    for idx, call, tag, S in _parsed(outcomes, calls, fb, "generalized_plant()"):
        p = {**DEFAULTS, **call.kwargs}
        ref = sol.generalized_plant(**p)
        if (S.ninputs, S.noutputs) != (3, 3):
            fb.append(f"{tag} expected 3 inputs [f1, f2, u] and 3 outputs [z1, z2, y], got {S.ninputs} "
                      f"inputs and {S.noutputs} outputs")
            continue
        w = resonance_safe_grid(ref)
        Gr = response(ref, w)[0]
        Gs, err = response(S, w)
        if err:
            fb.append(f"{tag} {err}")
            continue
        usable.add(idx)
        for (inp, out), (ok, msg) in zip(names, _channels(Gs, Gr, w, PLANT_INPUTS, PLANT_OUTPUTS,
                                                          _plant_hints(p))):
            if not ok:
                right[(inp, out)] = False
                # "channel f2 -> y ..." becomes "channel f2 -> y (sensor noise) ..."
                label = f"{inp} -> {out}"
                fb.append(f"{tag} " + msg.replace(label, f"{label} ({CHANNEL_ROLE[(inp, out)]})", 1))
        hint = permutation_hint(Gs, Gr, PLANT_INPUTS, PLANT_OUTPUTS, RTOL_MODEL)
        if hint:
            fb.append(f"{tag} hint: {hint}")
    if len(usable) < len(calls):
        right = {c: False for c in names}
    signal = [c for c in names if c not in ZERO_CHANNELS]
    n_ok = sum(right[c] for c in signal) - sum(not right[c] for c in ZERO_CHANNELS)
    if n_ok == len(signal) and all(right.values()):
        fb.insert(0, "correct: all 9 channels match with the defaults and with other arguments")
    elif usable and any(right[c] for c in ZERO_CHANNELS) and not any(right[c] for c in signal):
        fb.append("the channels that must be zero earn nothing by themselves")
    return POINTS["b"] * max(n_ok, 0) / len(signal), fb


# ----------------------------------------------------------------------------
# (c) H-infinity norm
# ----------------------------------------------------------------------------

def _norm_systems(draw=None):
    """(label, StateSpace) of the stable test systems of one run (a fresh draw without ``draw``)."""
    return (draw if draw is not None else _draw(np.random.default_rng()))["systems"]


@functools.lru_cache(maxsize=64)
def _norm_cached(key):
    A, B, C, D = (np.array(x, dtype=float).reshape(s) for x, s in key)
    return ref_hinf_norm(ss(A, B, C, D)).value


def _ref_norm(sys_):
    key = tuple((tuple(np.asarray(X, float).ravel().tolist()), np.asarray(X).shape)
                for X in (sys_.A, sys_.B, sys_.C, sys_.D))
    with _LOCK:
        return _norm_cached(key)


def _shortcuts(sys_, exp):
    """``(value, name, text)`` of the usual shortcuts for the norm of ``sys_``."""
    dc = float(np.linalg.norm(response(sys_, [0.0])[0][:, :, 0], 2))
    D = float(np.linalg.norm(np.asarray(sys_.D, float), 2))
    return [(dc, "the gain at DC", "that is the gain at DC, but the peak is elsewhere"),
            (D, "the gain at infinite frequency",
             "that is the gain at infinite frequency (the D matrix), but the peak is elsewhere"),
            (exp * exp, "the square of the norm", "that is the square of the norm")]


def _check_norm(outcomes, calls, systems):
    fb = []
    right, caught, easy = [], set(), []
    for call, oc, (label, sys_) in zip(calls, outcomes, systems):
        exp = _ref_norm(sys_)
        cuts = _shortcuts(sys_, exp)
        easy.append({name for v, name, _ in cuts if abs(v - exp) <= RTOL_NORM * exp})
        if not oc["ok"]:
            right.append(False)
            fb.append(f"[{label}] {oc['error']}")
            continue
        got = float(oc["value"])
        if np.isfinite(got) and abs(got - exp) <= RTOL_NORM * exp:
            right.append(True)
            continue
        right.append(False)
        msg = f"[{label}] your value {fmt(got)} is wrong"
        hit = [(name, t) for v, name, t in cuts
               if abs(got - v) <= 1e-6 * max(abs(v), 1e-300) and abs(v - exp) > RTOL_NORM * exp]
        caught.update(name for name, _ in hit)
        if not np.isfinite(got):
            msg += ": the system is stable, so its norm is finite"
        elif hit:
            msg += ": " + hit[0][1]
        elif got < exp:
            msg += (f", too low {_band(got, exp)}: a frequency grid misses narrow peaks; "
                    "refine near the peak or use the Hamiltonian bisection")
        else:
            msg += f", too high {_band(got, exp)}"
        fb.append(msg)
    n_ok = 0
    for (label, _), ok, e in zip(systems, right, easy):
        if ok and e and caught:
            fb.append(f"[{label}] 0 points: a shortcut ({sorted(caught)[0]}) was returned for another system, "
                      f"and this system's norm happens to be {sorted(e)[0]}")
        elif ok:
            n_ok += 1
    if n_ok == len(systems):
        fb.insert(0, f"correct: all {len(systems)} norms within a relative {RTOL_NORM:g}")
    return POINTS["c"] * n_ok / len(systems), fb


# ----------------------------------------------------------------------------
# (d) controller
# ----------------------------------------------------------------------------

_LOCK = threading.RLock()   # several submissions may be graded from threads; solve the LMIs once


def reference_problem():
    """The thesis plant (weights 28.6 and 0.02) and its optimal level, computed by :func:`mutext.hinf.hinfsyn`."""
    with _LOCK:
        return _reference_problem()


@functools.lru_cache(maxsize=1)
def _reference_problem():
    from mutext.examples import two_mass
    from mutext.hinf import hinfsyn
    P = two_mass.plant(two_mass.THESIS)
    return P, float(hinfsyn(P, 1, 1).gamma)


def _sampled_peak(CL, poles, P):
    """The largest gain of the closed loop sampled at the plant's natural frequencies, at its own poles'
    frequencies and on a log grid (``inf`` where the response cannot be evaluated)."""
    wp = np.abs(np.linalg.eigvals(np.asarray(P.A, float)).imag)
    w = np.unique(np.concatenate([[0.0], wp, np.abs(poles.imag), np.abs(poles), np.logspace(-1, 5, 200)]))
    G, err = response(CL, w)
    if err or not np.all(np.isfinite(G)):
        return np.inf
    return float(max(np.linalg.norm(G[:, :, k], 2) for k in range(G.shape[2])))


def _check_controller(outcomes, calls):
    oc = outcomes[0]
    if not oc["ok"]:
        return 0.0, [oc["error"]]
    big = _too_large(oc["value"], "controller()", MODEL_STATES, max_io=1)
    if big:
        return 0.0, [big]
    K, err = build_ss(oc["value"], "controller()")
    if err:
        return 0.0, [err]
    if (K.ninputs, K.noutputs) != (1, 1):
        return 0.0, [f"the controller must map the measurement y (1 input, m) to the force u (1 output, N); "
                     f"got {K.ninputs} inputs and {K.noutputs} outputs"]
    P, gamma = reference_problem()
    CL = lft_lower(P, K, 1, 1)
    poles = np.linalg.eigvals(np.asarray(CL.A, float)) if CL.nstates else np.zeros(0)
    # undamped open-loop modes computed from floating point must not pass as stable
    margin = 1e-9 * max(1.0, float(np.abs(poles).max()) if poles.size else 1.0)
    if poles.size and poles.real.max() >= -margin:
        worst = poles[np.argmax(poles.real)]
        return 0.0, [f"the closed loop (reference plant with your controller, u = K y) is unstable: pole at "
                     f"s = {fmt(worst)} 1/s; check the sign convention u = +K y"]
    norm = ref_hinf_norm(CL).value
    if not np.isfinite(norm):
        return 0.0, ["the closed loop (reference plant with your controller, u = K y) has an infinite H-infinity "
                     "norm: it is not stable (an undamped mode of the plant is left as it is)"]
    if _sampled_peak(CL, poles, P) > norm * (1.0 + 1e-3):
        return 0.0, ["the closed loop's frequency response exceeds its computed H-infinity norm: the loop is "
                     "numerically at the edge of stability (an undamped mode of the plant is not damped, or the "
                     "controller's realisation is badly conditioned); 0 points"]
    ratio = norm / gamma
    fb = [f"closed loop stable (1 point); closed-loop H-infinity norm {norm:.6g}, "
          f"{100 * (ratio - 1):+.3g} % from the optimal level"]
    if ratio <= CONTROLLER_FULL:
        return 3.0, fb + [f"correct: within {100 * (CONTROLLER_FULL - 1):g} % of the optimal level"]
    if ratio <= CONTROLLER_PARTIAL:
        return 2.0, fb + [f"within {100 * (CONTROLLER_PARTIAL - 1):g} % but not {100 * (CONTROLLER_FULL - 1):g} % "
                          "of the optimum: was it designed for the thesis weights 28.6 and 0.02?"]
    return 1.0, fb + ["more than 10 % above the optimal level: was the controller designed for the right "
                      "plant (weights, noise channel, input order [f1, f2, u])?"]


# ----------------------------------------------------------------------------

def prepare(rng=None):
    """The reference computations of a run (the same draws as :func:`questions` with an equal generator)."""
    reference_problem()
    if rng is not None:
        for _, s in _draw(rng)["systems"]:
            _ref_norm(s)


def questions(rng=None):
    """The four questions with their inputs drawn from ``rng`` (a fresh generator without one)."""
    draw = _draw(rng if rng is not None else np.random.default_rng())
    mech = draw["mech"]
    a_calls = [Call(f"parameter set {i + 1} of {len(mech)}", args=[p[k] for k in MECH]) for i, p in enumerate(mech)]
    b_labels = ["default arguments", "the masses and stiffnesses given, default weights", "all eight arguments given"]
    b_calls = [Call(lab, kwargs=dict(kw)) for lab, kw in zip(b_labels, draw["plant"])]
    systems = draw["systems"]
    c_calls = [Call(label, args=[{"__ss__": [np.asarray(getattr(s, X), float).tolist() for X in "ABCD"]}])
               for label, s in systems]
    d_calls = [Call("controller()")]
    return [
        Question("a", "mechanical_model", "state-space model of the two masses", POINTS["a"], "ss", a_calls,
                 lambda oc: _check_mechanical(oc, a_calls)),
        Question("b", "generalized_plant", "generalized plant with weights", POINTS["b"], "ss", b_calls,
                 lambda oc: _check_plant(oc, b_calls)),
        Question("c", "hinf_norm", "H-infinity norm", POINTS["c"], "float", c_calls,
                 lambda oc: _check_norm(oc, c_calls, systems)),
        Question("d", "controller", "H-infinity controller", POINTS["d"], "ss", d_calls,
                 lambda oc: _check_controller(oc, d_calls)),
    ]


EXERCISE = Exercise("ex01_two_mass_hinf", "H-infinity control of the two-mass system", questions,
                    stub="exercises/ex01_two_mass_hinf.py", prepare=prepare)
