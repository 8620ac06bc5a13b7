"""Grader of exercise ``ex01_two_mass_hinf``: H-infinity control of the two-mass system.

Questions (10 points):

(a) ``mechanical_model(m1, m2, k1, k2)``, 2 points: compared channel by
    channel through frequency responses at two parameter sets.
(b) ``generalized_plant(**params)``, 3 points: the same for the 9 channels of
    the generalized plant, with defaults and with other keyword arguments.
(c) ``hinf_norm(sys)``, 2 points: five stable systems, relative tolerance 1e-4.
(d) ``controller()``, 3 points: the closed loop is rebuilt here with the
    reference plant; 1 point for stability, 2 more if the closed-loop norm is
    within 2 % of the optimal level (1 more if within 10 %).

Partial credit is proportional to the channels or systems that are right.
"""
from __future__ import annotations

import functools
import threading

import numpy as np

from mutext.lti import hinf_norm as ref_hinf_norm
from mutext.lti import lft_lower, mck_to_ss, ss
from .compare import (build_ss, compare_responses, fmt, matches, permutation_hint, resonance_safe_grid, response,
                      returned)
from .core import Call, Exercise, Question
from .solutions import ex01_two_mass_hinf as sol

POINTS = {"a": 2.0, "b": 3.0, "c": 2.0, "d": 3.0}
RTOL_MODEL = 1e-4      # frequency responses: different state coordinates only change rounding
RTOL_NORM = 1e-4
CONTROLLER_FULL = 1.02     # closed-loop norm / optimal level for full marks
CONTROLLER_PARTIAL = 1.10

DEFAULTS = dict(m1=1.0, m2=2.0, k1=450.0, k2=175.0, f_max=10.0, eta_max=1e-4, x_max=0.035, u_max=50.0)
OTHER = dict(m1=1.5, m2=0.5, k1=300.0, k2=80.0, f_max=4.0, eta_max=2e-4, x_max=0.02, u_max=80.0)
MECH = ["m1", "m2", "k1", "k2"]


def _describe_params(p):
    return ", ".join(f"{k}={p[k]:g}" for k in p)


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
    for call, tag, S in returned(outcomes, calls, fb, build_ss, "mechanical_model()"):
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
        checks = compare_responses(Gs, Gr, w, ins, outs, rtol=RTOL_MODEL)
        n_ok += sum(c.ok for c in checks)
        if all(c.ok for c in checks):
            continue
        atol = 1e-9 * np.abs(Gr).max()
        hint = permutation_hint(Gs, Gr, ins, outs, RTOL_MODEL)
        for alt, text in _mech_alternatives(**p):
            if hint is None and matches(Gs, response(alt, w)[0], RTOL_MODEL, atol):
                hint = text
        fb += [f"{tag} {c.message}" for c in checks if not c.ok]
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


def _plant_hints(p):
    """(out, in) -> list of (factor, explanation) for constant-factor errors."""
    d = DEFAULTS
    rows = {
        0: [(p["x_max"] ** 2, f"the z1 weight looks like {p['x_max']:g} instead of 1/{p['x_max']:g}"),
            (p["x_max"], f"z1 looks unweighted: x1 must be divided by x_max = {p['x_max']:g} m"),
            (28.6 * p["x_max"], "the z1 weight looks like the thesis's rounded 28.6 instead of 1/x_max"),
            (p["x_max"] / d["x_max"], f"the z1 weight looks hard-coded to 1/{d['x_max']:g} instead of 1/x_max"),
            (-1.0, "the sign of z1 is flipped")],
        1: [(p["u_max"] ** 2, f"the z2 weight looks like {p['u_max']:g} instead of 1/{p['u_max']:g}"),
            (p["u_max"], f"z2 looks unweighted: u must be divided by u_max = {p['u_max']:g} N"),
            (p["u_max"] / d["u_max"], f"the z2 weight looks hard-coded to 1/{d['u_max']:g} instead of 1/u_max"),
            (-1.0, "the sign of z2 is flipped")],
        2: [(-1.0, "the sign of y is flipped")],
    }
    cols = {
        0: [(1 / p["f_max"], f"f1 is not scaled: the force on m1 is f_max*f1 with f_max = {p['f_max']:g} N"),
            (p["f_max"] ** -2, f"f1 looks scaled by 1/{p['f_max']:g} instead of {p['f_max']:g}"),
            (d["f_max"] / p["f_max"], f"f_max looks hard-coded to {d['f_max']:g} instead of the argument")],
        1: [(1 / p["eta_max"], f"f2 is not scaled: the noise is eta_max*f2 with eta_max = {p['eta_max']:g} m"),
            (p["eta_max"] ** -2, f"f2 looks scaled by 1/{p['eta_max']:g} instead of {p['eta_max']:g}"),
            (d["eta_max"] / p["eta_max"], f"eta_max looks hard-coded to {d['eta_max']:g} instead of the argument")],
        2: [(-1.0, "the sign of u is flipped")],
    }

    def hints(i, j):
        # a factor that is exactly 1 explains nothing (happens for the defaults)
        return [(f, t) for f, t in rows[i] + cols[j] if abs(f - 1.0) > 1e-9]
    return hints


def _check_plant(outcomes, calls):
    n_ok, n_all = 0, 9 * len(calls)
    fb = []
    for call, tag, S in returned(outcomes, calls, fb, build_ss, "generalized_plant()"):
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
        outs = [f"{o}" for o in PLANT_OUTPUTS]
        checks = compare_responses(Gs, Gr, w, PLANT_INPUTS, outs, rtol=RTOL_MODEL, hints=_plant_hints(p))
        n_ok += sum(c.ok for c in checks)
        for c in checks:
            if not c.ok:
                # "channel f2 -> y differs ..." becomes "channel f2 -> y (sensor noise) differs ..."
                label = f"{c.inp} -> {c.out}"
                fb.append(f"{tag} " + c.message.replace(label, f"{label} ({CHANNEL_ROLE[(c.inp, c.out)]})", 1))
        hint = permutation_hint(Gs, Gr, PLANT_INPUTS, PLANT_OUTPUTS, RTOL_MODEL)
        if hint:
            fb.append(f"{tag} hint: {hint}")
    if n_ok == n_all:
        fb.insert(0, "correct: all 9 channels match with the default and with other arguments")
    return POINTS["b"] * n_ok / n_all, fb


# ----------------------------------------------------------------------------
# (c) H-infinity norm
# ----------------------------------------------------------------------------

def _norm_systems():
    """(label, StateSpace) of stable test systems, chosen to catch the usual shortcuts."""
    out = []
    out.append(("first-order low-pass 2/(s+1), peak at DC", ss([[-1.0]], [[1.0]], [[2.0]], [[0.0]])))
    wn, z = 10.0, 1e-3
    out.append((f"lightly damped resonance (zeta={z:g}, wn={wn:g} rad/s)",
                ss([[0.0, 1.0], [-wn * wn, -2 * z * wn]], [[0.0], [wn * wn]], [[1.0, 0.0]], [[0.0]])))
    out.append(("(s+0.1)/(s+1), peak at infinite frequency (the D matrix)",
                ss([[-1.0]], [[1.0]], [[-0.9]], [[1.0]])))
    rng = np.random.default_rng(3)
    A = rng.standard_normal((4, 4))
    A -= (np.linalg.eigvals(A).real.max() + 0.3) * np.eye(4)
    out.append(("random 2x2 MIMO system with 4 states and D != 0",
                ss(A, rng.standard_normal((4, 2)), rng.standard_normal((2, 4)), 0.3 * rng.standard_normal((2, 2)))))
    M = np.diag([1.0, 2.0])
    K = np.array([[450.0, -450.0], [-450.0, 625.0]])
    out.append(("damped two-mass model [f_e, u] -> [x1, x2] (damping 0.02 K)",
                mck_to_ss(M, 0.02 * K, K, {"f_e": 0, "u": 1}, {"x1": 0, "x2": 1})))
    return out


def _check_norm(outcomes, calls, systems):
    n_ok = 0
    fb = []
    for call, oc, (label, sys_) in zip(calls, outcomes, systems):
        ref = ref_hinf_norm(sys_)
        exp = ref.value
        if not oc["ok"]:
            fb.append(f"[{label}] {oc['error']}")
            continue
        got = oc["value"]
        if np.isfinite(got) and abs(got - exp) <= RTOL_NORM * exp:
            n_ok += 1
            continue
        where = "infinite frequency" if not np.isfinite(ref.frequency) else f"{ref.frequency:.4g} rad/s"
        msg = f"[{label}] expected {exp:.6g} (peak at {where}), got {fmt(got) if np.isfinite(got) else got}"
        dc = np.linalg.norm(response(sys_, [0.0])[0][:, :, 0], 2)
        D = np.linalg.norm(np.asarray(sys_.D, float), 2)
        if not np.isfinite(got):
            msg += ": the system is stable, so its norm is finite"
        elif abs(got - dc) <= 1e-6 * max(dc, 1e-300) and abs(dc - exp) > RTOL_NORM * exp:
            msg += ": that is the gain at DC, but the peak is elsewhere"
        elif abs(got - D) <= 1e-6 * max(D, 1e-300) and abs(D - exp) > RTOL_NORM * exp:
            msg += ": that is the gain at infinite frequency (the D matrix), but the peak is elsewhere"
        elif abs(got - exp * exp) <= RTOL_NORM * exp * exp:
            msg += ": that is the square of the norm"
        elif got < exp:
            msg += (f" ({100 * (1 - got / exp):.3g} % too low): a frequency grid misses narrow peaks; "
                    "refine near the peak or use the Hamiltonian bisection")
        else:
            msg += f" ({100 * (got / exp - 1):.3g} % too high)"
        fb.append(msg)
    if n_ok == len(systems):
        fb.insert(0, f"correct: all {len(systems)} norms within a relative {RTOL_NORM:g}")
    return POINTS["c"] * n_ok / len(systems), fb


# ----------------------------------------------------------------------------
# (d) controller
# ----------------------------------------------------------------------------

_LOCK = threading.Lock()   # several submissions may be graded from threads; solve the LMIs once


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


def _check_controller(outcomes, calls):
    oc = outcomes[0]
    if not oc["ok"]:
        return 0.0, [oc["error"]]
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
    ratio = norm / gamma
    fb = [f"closed loop stable (1 point); closed-loop H-infinity norm {norm:.6g}, optimal level {gamma:.6g} "
          f"({100 * (ratio - 1):+.3g} %)"]
    if ratio <= CONTROLLER_FULL:
        return 3.0, fb + [f"correct: within {100 * (CONTROLLER_FULL - 1):g} % of the optimal level"]
    if ratio <= CONTROLLER_PARTIAL:
        return 2.0, fb + [f"within {100 * (CONTROLLER_PARTIAL - 1):g} % but not {100 * (CONTROLLER_FULL - 1):g} % "
                          "of the optimum: was it designed for the thesis weights 28.6 and 0.02?"]
    return 1.0, fb + ["more than 10 % above the optimal level: was the controller designed for the right "
                      "plant (weights, noise channel, input order [f1, f2, u])?"]


# ----------------------------------------------------------------------------

def questions(rng=None):
    """The four questions with their test inputs."""
    a_calls = [Call("m1=1, m2=2, k1=450, k2=175", args=[DEFAULTS[k] for k in MECH]),
               Call("m1=1.5, m2=0.5, k1=300, k2=80", args=[OTHER[k] for k in MECH])]
    b_calls = [Call("default arguments"), Call(_describe_params(OTHER), kwargs=dict(OTHER))]
    systems = _norm_systems()
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
                    stub="exercises/ex01_two_mass_hinf.py", prepare=lambda rng=None: reference_problem())
