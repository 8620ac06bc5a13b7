r"""Grader of exercise ``ex08_mbi``: model-based identification on the three-mass rig (thesis ch. 3).

Questions (10 points):

(a) ``mbi_plant(rig, Wz)``, 3 points: the plant of thesis Fig. 3.3, inputs
    ``[w_unc, w, n, u]``, outputs ``[z_unc, z, z_u, y]``, for two drawn rigs
    (ports, parameters, weights).  The uncertainty channel is closed with
    ``w_unc = delta z_unc`` for five ``delta`` in ``[-1, 1]`` (any scaling of
    the channel passes) and the nine channels ``[w, n, u] -> [z, z_u, y]``
    are compared with the reference at frequencies around the rigs' modes
    (relative tolerance 1e-4); a channel counts when it is right for every
    ``delta``; 1.5 points a rig, shared by the six channels that carry a
    signal, and each of the three that must be zero but is not takes a share
    away.
(b) ``synthesize(rig, Wz, omega)``, 3 points: the student's ``K`` is closed
    around the reference plant here: 2 points when the loop is stable and the
    peak of the mu upper bound (:func:`mutext.mu.mu_sweep`, one real block and
    the full ``2 x 2`` performance block) is at most 1, 1 point when at most
    1.1; 1 more when ``K(j omega)`` follows the rig's :math:`D_u` on the
    identifiable band (weighted RMS relative error within
    :func:`b_tolerance`: 2 % plus what the uncertainty of the true rig allows).
(c) ``smallest_wz(rig, wz_low, wz_high, omega)``, 2 points: the smallest
    ``Wz`` with ``mu <= 1``, accepted between the floor of
    :func:`mutext.mbi.wz_floor` (below it no controller reaches ``mu <= 1``:
    the spread of the true rigs alone is larger) and 1.15 times the
    reference's search (:func:`reference_wz`; D-K's first K step reaches
    ``mu <= 1`` within 10 % of the floor on these rigs).
(d) ``read_controller(rig, Wz, K, omega)``, 2 points: the mass-damper-spring
    fit of a given ``K`` on its identifiable band (1.2: the fit's response on
    the band within 2 % of :func:`mutext.mbi.fit_impedance`'s) and the band
    edges (0.8: each within one grid point of :func:`mutext.mbi.identifiable_band`'s, counted with a
    right fit only: a spring's band reaches down to the grid's first point).

Inputs are drawn per run from the generator the grader is given: the rig of
(b)-(d) is one of the thesis's trials 1a, 1b, 2 and 3 (a spring, the spring
the other way, a mass or a damper wrong in the engineering model) with the
size of the difference drawn 0.6-1.4 times the thesis's, the uncertainty
1-3 %, the bound ``Wz`` of (b) 1.8-2.5 times the floor and the bracket of
(c) so that neither end nor the means of the bracket lie in the accepted
window.  The two rigs of (a) have their ports and all nine parameters drawn
(10-30 % around Table 3.1), the changed parameter and the weights too.  The
``K`` of (d) is the drawn :math:`D_u` with a second-order roll-off at five
times the top of the band (a controller as D-K returns it, without the wait), so a fit
over the whole grid instead of the band is wrong, and is named.

No D-K result is stored: the reference search of (c) runs at grading time
(:data:`Exercise.prepare`, while the submission runs; one to four K steps
and mu sweeps of a few seconds each).  The references are the library's (:mod:`mutext.mbi`,
:mod:`mutext.uncertain`, :mod:`mutext.mu`, :mod:`mutext.dk`); the reference
solution builds the plant and reads ``K`` with numpy and python-control.

Feedback names the mistake without a reference value: ``+u`` instead of
``-u`` (``K`` of the opposite sign), the error not divided by ``Wz`` or not
multiplied by ``Ww``, the engineering response added instead of subtracted,
the uncertainty closing with the wrong sign, ``mu > 1``, an unstable loop, a
``Wz`` below the floor (the bisection kept the wrong end), one that is not the
smallest, Wz in mm, the fit over the whole grid, the band from ``|s| >= 1``,
Hz for rad/s.
"""
from __future__ import annotations

import dataclasses
import functools
import math
import threading

import numpy as np

from mutext.lti import freqresp, is_stable, lft_lower, mck_to_ss, ss
from mutext.response import frequency_grid
from .compare import as_array, build_ss, response, returned
from .core import Call, Exercise, Question

POINTS = {"a": 3.0, "b": 3.0, "c": 2.0, "d": 2.0}
PARAMS = ("m1", "m2", "m3", "k1", "k2", "k3", "c1", "c2", "c3")
RTOL_MODEL = 1e-4
DELTAS = (-1.0, -0.3, 0.0, 0.6, 1.0)
MU_FULL, MU_PARTIAL = 1.0, 1.1
WZ_WINDOW = 1.15
RTOL_FIT = 0.02
MAX_K_STATES = 60
MAX_PLANT_STATES = 30
TRIALS = ("1a", "1b", "2", "3")
REGULARIZATION = 1e-4
N_GRID = 120
INS, OUTS = ["w", "n", "u"], ["z", "z_u", "y"]


# ----------------------------------------------------------------------------
# rigs and reference plants (mutext.uncertain, mutext.mbi)
# ----------------------------------------------------------------------------

def _matrices(v):
    M = np.diag([v["m1"], v["m2"], v["m3"]])
    K = np.array([[v["k1"], -v["k1"], 0.0], [-v["k1"], v["k1"] + v["k2"], -v["k2"]],
                  [0.0, -v["k2"], v["k2"] + v["k3"]]])
    return M, np.diag([v["c1"], v["c2"], v["c3"]]), K


def true_model(rig):
    """The true rig as an uncertain model (:func:`mutext.uncertain.uncertain_mck`): input ``fe``, output ``xm``."""
    from mutext.uncertain import UncertainParameter, uncertain_mck
    base = dict(zip(PARAMS, rig["true"]))
    name = rig["changed"]
    return uncertain_mck(lambda v: _matrices({**base, **v}), [UncertainParameter(name, base[name], rel=rig["rel"])],
                         inputs={"fe": rig["excitation"]}, outputs={"xm": rig["measurement"]})


def engineering_model(rig):
    M, C, K = _matrices(dict(zip(PARAMS, rig["engineering"])))
    return mck_to_ss(M, C, K, inputs={"fe": rig["excitation"], "fu": rig["control"]},
                     outputs={"xm": rig["measurement"], "xu": rig["control"]})


def reference_plant(rig, Wz):
    """:func:`mutext.mbi.mbi_plant` with the rig's fixed ``eps_u`` and ``eps_y`` (an ``MBIPlant``)."""
    from mutext.mbi import mbi_plant
    p = mbi_plant(true_model(rig), engineering_model(rig), excitation="fe", measurement="xm", control_input="fu",
                  control_output="xu", Ww=rig["Ww"], Wz=Wz, regularization=REGULARIZATION)
    D = np.array(p.P.D, float)
    D[2, 3], D[3, 2] = rig["eps_u"], rig["eps_y"]
    P = ss(p.P.A, p.P.B, p.P.C, D, inputs=list(p.P.input_labels), outputs=list(p.P.output_labels))
    return dataclasses.replace(p, P=P, eps_u=rig["eps_u"], eps_y=rig["eps_y"])


def closed_channels(P, delta):
    """``[w, n, u] -> [z, z_u, y]`` of a plant with its first input and output closed by ``w_unc = delta z_unc``."""
    A, B, C, D = (np.asarray(X, float) for X in (P.A, P.B, P.C, P.D))
    e = 1.0 - delta * D[0, 0]
    if abs(e) < 1e-12:
        return None
    f = delta / e
    A2 = A + f * np.outer(B[:, 0], C[0])
    B2 = B[:, 1:] + f * np.outer(B[:, 0], D[0, 1:])
    C2 = C[1:] + f * np.outer(D[1:, 0], C[0])
    D2 = D[1:, 1:] + f * np.outer(D[1:, 0], D[0, 1:])
    return ss(A2, B2, C2, D2)


@functools.lru_cache(maxsize=16)
def _floor_cached(key):
    from mutext.mbi import wz_floor
    rig = _rig_of(key)
    return float(wz_floor(true_model(rig), excitation="fe", measurement="xm", Ww=rig["Ww"]).value)


def _key(rig):
    return tuple((k, tuple(v) if isinstance(v, list) else v) for k, v in sorted(rig.items()))


def _rig_of(key):
    return {k: (list(v) if isinstance(v, tuple) else v) for k, v in key}


def floor(rig):
    """The certified floor of ``Wz`` (:func:`mutext.mbi.wz_floor`)."""
    return _floor_cached(_key(rig))


def du(rig):
    """``{"dm", "dc", "dk"}``: the true minus the engineering parameters of cart 3 (what ``K`` stands for)."""
    t, e = dict(zip(PARAMS, rig["true"])), dict(zip(PARAMS, rig["engineering"]))
    return {"dm": t["m3"] - e["m3"], "dc": t["c3"] - e["c3"], "dk": t["k3"] - e["k3"]}


def grid(rig):
    """The ``N_GRID`` frequencies [rad/s] of (b)-(d): a decade either side of the rigs' modes."""
    A = np.asarray(engineering_model(rig).A, float)
    At = np.asarray(true_model(rig).nominal().A, float)
    poles = np.concatenate([np.linalg.eigvals(A), np.linalg.eigvals(At)])
    return np.round(frequency_grid(n=N_GRID, poles=poles), 8)


_LOCK = threading.RLock()


def _mu(P, K, structure, omega):
    from mutext.mu import mu_sweep
    return float(mu_sweep(lft_lower(P, K, 1, 1), structure, omega).peak_upper)


def k_step(P):
    """The first K step of D-K (unit scalings): the H-infinity controller of python-control/slycot (SB10AD)."""
    import control as ct
    return ct.hinfsyn(P, 1, 1)[0]


@functools.lru_cache(maxsize=8)
def _reference_wz_cached(key):
    from mutext.mu import mu_sweep
    rig = _rig_of(key[0])
    omega = np.array(key[1])
    Wz = 1.1 * floor(rig)
    runs = []
    for _ in range(4):
        p = reference_plant(rig, Wz)
        K = k_step(p.P)
        mu = float(mu_sweep(lft_lower(p.P, K, 1, 1), p.structure, omega, lower="none").peak_upper)
        runs.append((Wz, mu))
        if mu <= 1.0:
            return Wz, runs
        Wz = Wz * mu * 1.03
    raise RuntimeError(f"the reference W_z search did not reach mu <= 1: {runs}")   # pragma: no cover


def reference_wz(rig, omega):
    """The smallest ``Wz`` at which the reference reaches ``mu <= 1``: tried first at 1.1 times the floor,
    then by secant steps ``Wz mu`` (mu scales like ``1/Wz``) with 3 % to spare; each try is D-K's first
    step (:func:`k_step`) and the peak of :func:`mutext.mu.mu_sweep`'s upper bound."""
    with _LOCK:
        return _reference_wz_cached((_key(rig), tuple(np.asarray(omega, float).tolist())))[0]


def b_tolerance(rig):
    """The accepted weighted RMS relative error of ``K`` against ``D_u``: 2 % plus 1.5 times the change of
    ``D_u`` that the uncertainty of the true parameter allows."""
    t = dict(zip(PARAMS, rig["true"]))
    d = du(rig)
    key = {"k3": "dk", "m3": "dm", "c3": "dc"}[rig["changed"]]
    return 0.02 + 1.5 * rig["rel"] * abs(t[rig["changed"]]) / abs(d[key])


# ----------------------------------------------------------------------------
# inputs drawn per run
# ----------------------------------------------------------------------------

def _table():
    from mutext.examples.three_mass import TABLE_3_1
    return [float(getattr(TABLE_3_1, n)) for n in PARAMS]


def _trial(name):
    from mutext.examples.three_mass import TRIALS as T
    t = T[name]
    return [float(getattr(t.true, n)) for n in PARAMS], [float(getattr(t.engineering, n)) for n in PARAMS]


def _regularize(rig, Wz):
    """``eps_u`` and ``eps_y`` as :func:`mutext.mbi.mbi_plant` scales them at ``Wz``."""
    from mutext.mbi import mbi_plant
    p = mbi_plant(true_model({**rig, "eps_u": 0.0, "eps_y": 0.0}), engineering_model(rig), excitation="fe",
                  measurement="xm", control_input="fu", control_output="xu", Ww=rig["Ww"], Wz=Wz,
                  regularization=REGULARIZATION)
    return float(f"{p.eps_u:.4g}"), float(f"{p.eps_y:.4g}")


def draw_a_rig(rng):
    """A rig for (a): all parameters 10-30 % around Table 3.1, ports and the changed parameter drawn."""
    base = np.array(_table())
    true = [float(f"{x:.5g}") for x in base * rng.uniform(0.7, 1.3, base.size)]
    eng = [float(f"{x:.5g}") for x in np.array(true) * rng.uniform(0.6, 1.4, base.size)]
    changed = str(rng.choice(["k3", "m3", "c3"]))
    rig = dict(true=true, engineering=eng, changed=changed, rel=float(f"{rng.uniform(0.01, 0.1):.3g}"),
               excitation=int(rng.integers(3)), measurement=int(rng.integers(3)), control=int(rng.integers(1, 3)),
               Ww=float(f"{rng.uniform(0.5, 5.0):.3g}"))
    Wz = float(f"{rng.uniform(1e-4, 2e-3):.3g}")
    eu, ey = _regularize(rig, Wz)
    rig["eps_u"], rig["eps_y"] = float(f"{eu * rng.uniform(0.5, 2):.4g}"), float(f"{ey * rng.uniform(0.5, 2):.4g}")
    return rig, Wz


def draw_rig(rng):
    """The rig of (b)-(d): a thesis trial with the size of the change and the uncertainty drawn."""
    name = TRIALS[int(rng.integers(len(TRIALS)))]
    true, eng = _trial(name)
    i = int(np.flatnonzero(np.array(true) != np.array(eng))[0])
    eng[i] = float(f"{true[i] + (eng[i] - true[i]) * rng.uniform(0.6, 1.4):.5g}")
    rig = dict(true=true, engineering=eng, changed=PARAMS[i], rel=float(f"{rng.uniform(0.01, 0.03):.3g}"),
               excitation=0, measurement=0, control=2, Ww=1.0)
    fl = floor(rig)
    rig["eps_u"], rig["eps_y"] = _regularize(rig, 1.5 * fl)
    return name, rig


def _bracket(rng, fl):
    lo = fl * rng.uniform(0.5, 0.9)
    a = max(3.0, 2.6 / (lo / fl))                   # sqrt(lo hi) at least 1.6 times the floor
    hi = fl * rng.uniform(a, a + 2.0)
    return float(f"{lo:.4g}"), float(f"{hi:.4g}")


def d_controller(rig, omega, Wz):
    """The ``K`` of (d): ``D_u(s)`` with a double pole at five times the top of its identifiable band (the
    band of ``D_u`` rolled off above the grid, found first), as a controller from D-K looks on and off its band."""
    import control as ct
    from mutext.mbi import identifiable_band
    d = du(rig)
    num = [d["dm"], d["dc"], d["dk"]]

    def rolled(p):
        return ss(*(np.asarray(X, float) for X in ct.ssdata(ct.tf(num, np.polymul([1 / p, 1], [1 / p, 1])))))
    _, band = identifiable_band(reference_plant(rig, Wz), rolled(3.0 * float(np.max(omega))), omega)
    return rolled(5.0 * float(np.max(omega[band])))


def _draw(rng):
    a = [draw_a_rig(rng) for _ in range(2)]
    name, rig = draw_rig(rng)
    fl = floor(rig)
    omega = grid(rig)
    return dict(a=a, trial=name, rig=rig, Wz_b=float(f"{fl * rng.uniform(1.8, 2.5):.4g}"),
                bracket=_bracket(rng, fl), omega=omega, Wz_d=float(f"{fl * rng.uniform(1.2, 2.0):.4g}"))


def prepare(rng=None):
    """The reference search of (c) (the same draws as :func:`questions` with an equal generator)."""
    if rng is not None:
        d = _draw(rng)
        reference_wz(d["rig"], d["omega"])


# ----------------------------------------------------------------------------
# (a)
# ----------------------------------------------------------------------------

def _a_alternatives(rig, Wz):
    """Plants of the usual mistakes, with the explanation."""
    P = reference_plant(rig, Wz).P
    A, B, C, D = (np.array(X, float) for X in (P.A, P.B, P.C, P.D))
    nt = true_model(rig).P.nstates
    out = []
    B1 = B.copy()
    B1[:, 3] = -B1[:, 3]
    out.append((ss(A, B1, C, D), "u enters the engineering model as +u; the plant applies -u, so that K stands "
                                 "for the missing dynamic stiffness"))
    C1 = C.copy()
    C1[1] *= Wz
    D1 = D.copy()
    D1[1] *= Wz
    out.append((ss(A, B, C1, D1), "z is not divided by Wz"))
    B2 = B.copy()
    B2[:, 1] /= rig["Ww"]
    D2 = D.copy()
    D2[:, 1] /= rig["Ww"]
    out.append((ss(A, B2, C, D2), "the excitation is not multiplied by Ww"))
    C3 = C.copy()
    C3[1, nt:] = -C3[1, nt:]
    out.append((ss(A, B, C3, D), "z is x_t + x_e; the error is x_t - x_e"))
    B4 = B.copy()
    B4[:, 0] = -B4[:, 0]
    D4 = D.copy()
    D4[:, 0] = -D4[:, 0]
    out.append((ss(A, B4, C, D4), "the uncertainty channel closes with the wrong sign: w_unc = delta z_unc must "
                                  "give p0 (1 + rel delta)"))
    return out


def _a_responses(P, w):
    """``{delta: (3, 3, nw)}`` responses of the closed channels (None where not well posed)."""
    out = {}
    for dl in DELTAS:
        S = closed_channels(P, dl)
        out[dl] = None if S is None else freqresp(S, w)
    return out


def _check_a(outcomes, calls):
    per = POINTS["a"] / len(calls)
    score, fb = 0.0, []
    for call, tag, value in returned(outcomes, calls, fb):
        if isinstance(value, dict) and len(value.get("A") or []) > MAX_PLANT_STATES:
            fb.append(f"{tag} the plant has more than {MAX_PLANT_STATES} states (the two rigs have 12): not evaluated")
            continue
        S, err = build_ss(value, "mbi_plant()")
        if err:
            fb.append(f"{tag} {err}")
            continue
        if (S.ninputs, S.noutputs) != (4, 4):
            fb.append(f"{tag} expected 4 inputs [w_unc, w, n, u] and 4 outputs [z_unc, z, z_u, y], got "
                      f"{S.ninputs} inputs and {S.noutputs} outputs")
            continue
        w = call.grid
        got = _a_responses(S, w)
        ref = call.ref
        ok = np.ones((3, 3), bool)
        for dl in DELTAS:
            if got[dl] is None or not np.all(np.isfinite(got[dl])):
                ok[:] = False
                break
            atol = 1e-9 * np.abs(ref[dl]).max()
            ok &= np.all(np.abs(got[dl] - ref[dl]) <= RTOL_MODEL * np.abs(ref[dl]) + atol, axis=2)
        # the channels that carry a signal share the points; a structurally zero one that is not zero takes
        # a share away (a zero plant earns nothing)
        zero = np.all([np.abs(ref[dl]).max(axis=2) <= 1e-12 * np.abs(ref[dl]).max() for dl in DELTAS], axis=0)
        n_sig = int((~zero).sum())
        score += per * max(int((ok & ~zero).sum()) - int((~ok & zero).sum()), 0) / n_sig
        if ok.all():
            continue
        named = None
        for alt, text in call.alternatives:
            if all(got[dl] is not None and np.all(np.abs(got[dl] - alt[dl]) <= RTOL_MODEL * np.abs(alt[dl])
                                                  + 1e-9 * np.abs(alt[dl]).max()) for dl in DELTAS):
                named = text
                break
        bad = [f"{INS[j]} -> {OUTS[i]}" for i in range(3) for j in range(3) if not ok[i, j]]
        fb.append(f"{tag} {len(bad)} of 9 channels differ ({', '.join(bad)})" + (f": {named}" if named else ""))
    if not fb:
        fb = ["correct: all nine channels of both rigs, for every delta"]
    return score, fb


# ----------------------------------------------------------------------------
# (b)
# ----------------------------------------------------------------------------

def _k_from(value, tag, fb, what):
    if isinstance(value, dict) and len(value.get("A") or []) > MAX_K_STATES:
        fb.append(f"{tag} K has more than {MAX_K_STATES} states: not evaluated")
        return None
    K, err = build_ss(value, what)
    if err:
        fb.append(f"{tag} {err}")
        return None
    if (K.ninputs, K.noutputs) != (1, 1):
        fb.append(f"{tag} K must have one input (y) and one output (u), got {K.ninputs} and {K.noutputs}")
        return None
    return K


def _check_b(outcomes, calls):
    from mutext.mbi import identifiable_band, relative_error
    score, fb = 0.0, []
    for call, tag, value in returned(outcomes, calls, fb):
        K = _k_from(value, tag, fb, "synthesize()")
        if K is None:
            continue
        p = call.plant
        CL = lft_lower(p.P, K, 1, 1)
        if not is_stable(CL):
            fb.append(f"{tag} the loop of the plant with this K is unstable (is u applied as -u on the engineering "
                      "model, and K closed as u = +K y?)")
            continue
        mu = _mu(p.P, K, p.structure, call.omega)
        if mu <= MU_FULL:
            score += 2.0
        elif mu <= MU_PARTIAL:
            score += 1.0
            fb.append(f"{tag} the peak of the mu upper bound with your K is {mu:.3f}: above 1, robust performance "
                      "is not certified at this Wz (iterate D-K further or on a finer grid)")
        else:
            fb.append(f"{tag} the peak of the mu upper bound with your K is {mu:.3f}: far above 1")
        if mu > MU_PARTIAL:
            continue
        s, band = identifiable_band(p, K, call.omega)
        if band.sum() < 3:
            fb.append(f"{tag} K has almost no identifiable band on the grid")
            continue
        wb, sb = call.omega[band], s[band]
        err = relative_error(K, call.du, wb, weight=sb)
        if err <= call.tol:
            score += 1.0
        elif relative_error(-np.asarray(freqresp(K, wb)[0, 0]), call.du, wb, weight=sb) <= call.tol:
            fb.append(f"{tag} K has the opposite sign of the missing dynamic stiffness: the plant applies -u")
        else:
            fb.append(f"{tag} on its identifiable band K is off the rig's missing dynamics by {err:.1%} (weighted "
                      "RMS), more than the uncertainty allows")
    if not fb:
        fb = ["correct: stable, mu <= 1, and K is the missing dynamic stiffness on its band"]
    return score, fb


# ----------------------------------------------------------------------------
# (c)
# ----------------------------------------------------------------------------

def _check_c(outcomes, calls):
    score, fb = 0.0, []
    for call, tag, value in returned(outcomes, calls, fb):
        x = float(value)
        fl = call.floor
        ref = reference_wz(call.rig, call.omega)
        hi = WZ_WINDOW * ref
        if not math.isfinite(x) or x <= 0:
            fb.append(f"{tag} Wz must be a positive number of metres")
        elif fl <= x <= hi:
            score += POINTS["c"]
        elif fl <= x * 1e-3 <= hi:
            fb.append(f"{tag} Wz looks like millimetres; SI units (m) are asked")
        elif x < fl:
            fb.append(f"{tag} Wz is below the floor set by the spread of the true rigs: there mu > 1 for every "
                      "controller (did the bisection keep the end with mu > 1?)")
        elif abs(x - call.args[2]) <= 1e-9 * x:
            fb.append(f"{tag} this is the upper end of the bracket: the smallest Wz with mu <= 1 is asked")
        else:
            fb.append(f"{tag} mu <= 1 holds at this Wz but it is not the smallest: mu is well below 1 there "
                      f"(search down to within {WZ_WINDOW - 1:.0%})")
    if not fb:
        fb = ["correct: the smallest Wz, within the accepted window above the floor"]
    return score, fb


# ----------------------------------------------------------------------------
# (d)
# ----------------------------------------------------------------------------

def _check_d(outcomes, calls):
    score, fb = 0.0, []
    for call, tag, x in returned(outcomes, calls, fb, as_array, "read_controller()"):
        x = x.ravel()
        if x.size != 5 or not np.all(np.isfinite(x)):
            fb.append(f"{tag} expected five finite numbers [dm, dc, dk, omega_lo, omega_hi], got {x.size}")
            continue
        dm, dc, dk, lo, hi = (float(v) for v in x)
        wb = call.band_omega
        ref = call.fit.response(wb)
        got = dk + 1j * wb * dc - wb ** 2 * dm
        err = float(np.linalg.norm(got - ref) / np.linalg.norm(ref))
        if err <= RTOL_FIT:
            score += 1.2
        else:
            named = ""
            if float(np.linalg.norm(got + ref) / np.linalg.norm(ref)) <= RTOL_FIT:
                named = ": it has the opposite sign (K stands for +D_u)"
            elif all(abs(a - b) <= RTOL_FIT * max(abs(b), 1e-12) for a, b in zip((dm, dc, dk), call.whole)
                     if abs(b) > 1e-9):
                named = ": this is the fit over the whole grid; fit on the identifiable band only"
            fb.append(f"{tag} the mass-damper-spring fit differs from the reference by more than "
                      f"{RTOL_FIT:.0%} on the band{named}")
        w = call.omega
        k_lo, k_hi = call.band_index

        def near(v, k):
            j = int(np.argmin(np.abs(w - v)))
            return bool(abs(j - k) <= 1 and abs(v - w[j]) <= 0.01 * w[j])
        if err > RTOL_FIT:
            # a spring's band reaches down to the grid's first point: the edges count with the fit only
            fb.append(f"{tag} the band edges are scored with a right fit only")
            continue
        edges = int(near(lo, k_lo)) + int(near(hi, k_hi))
        score += 0.4 * edges
        if edges < 2:
            msg = f"{tag} {'one band edge is' if edges == 1 else 'the band edges are'} not within one grid point"
            if near(lo, call.s_band[0]) and near(hi, call.s_band[1]):
                msg += ": the band is where |s K| >= 1, not |s| >= 1"
            elif any(near(v * 2 * math.pi, k) for v, k in ((lo, k_lo), (hi, k_hi))):
                msg += ": the frequencies are in Hz; rad/s is asked"
            fb.append(msg)
    if not fb:
        fb = ["correct: the fit on the band and the band edges"]
    return score, fb


def _k_arg(K):
    return {"__ss__": [np.asarray(getattr(K, X), float).tolist() for X in "ABCD"]}


def questions(rng=None):
    """The four questions, drawn from ``rng``; the D-K reference of (c) runs later (``prepare``, checks)."""
    from mutext.mbi import fit_impedance, identifiable_band
    rng = np.random.default_rng() if rng is None else rng
    d = _draw(rng)
    a_calls = []
    for n, (rig, Wz) in enumerate(d["a"]):
        call = Call(f"rig {n + 1} of 2", [rig, Wz])
        P = reference_plant(rig, Wz).P
        poles = np.linalg.eigvals(np.asarray(P.A, float))
        call.grid = frequency_grid(n=40, poles=poles, margin=(10.0, 10.0), avoid=0.0)
        call.ref = _a_responses(P, call.grid)
        call.alternatives = [(_a_responses(S, call.grid), text) for S, text in _a_alternatives(rig, Wz)]
        a_calls.append(call)
    rig, omega = d["rig"], d["omega"]
    label = f"trial {d['trial']}-like rig"
    call = Call(label, [rig, d["Wz_b"], omega.tolist()])
    call.plant = reference_plant(rig, d["Wz_b"])
    call.omega = omega
    call.du = du(rig)
    call.tol = b_tolerance(rig)
    b_calls = [call]
    lo, hi = d["bracket"]
    call = Call(label, [rig, lo, hi, omega.tolist()])
    call.rig, call.omega, call.floor = rig, omega, floor(rig)
    c_calls = [call]
    K = d_controller(rig, omega, d["Wz_d"])
    p = reference_plant(rig, d["Wz_d"])
    s, band = identifiable_band(p, K, omega)
    call = Call(label, [rig, d["Wz_d"], _k_arg(K), omega.tolist()])
    call.omega = omega
    call.band_omega = omega[band]
    call.fit = fit_impedance(K, omega[band], weight=s[band])
    whole = fit_impedance(K, omega)
    call.whole = (whole.dm, whole.dc, whole.dk)
    idx = np.flatnonzero(band)
    call.band_index = (int(idx[0]), int(idx[-1]))
    sidx = np.flatnonzero(s >= 1.0)
    call.s_band = (int(sidx[0]), int(sidx[-1])) if sidx.size else (-10, -10)
    d_calls = [call]
    return [
        Question("a", "mbi_plant", "the plant of thesis Fig. 3.3", POINTS["a"], "ss", a_calls,
                 lambda oc: _check_a(oc, a_calls)),
        Question("b", "synthesize", "D-K: a controller with mu <= 1", POINTS["b"], "ss", b_calls,
                 lambda oc: _check_b(oc, b_calls)),
        Question("c", "smallest_wz", "the W_z rule: the smallest Wz with mu <= 1", POINTS["c"], "float", c_calls,
                 lambda oc: _check_c(oc, c_calls)),
        Question("d", "read_controller", "K read as mass, damper and spring on its identifiable band", POINTS["d"],
                 "array", d_calls, lambda oc: _check_d(oc, d_calls)),
    ]


EXERCISE = Exercise("ex08_mbi", "Model-based identification on the three-mass rig: plant, D-K, the W_z rule, K",
                    questions, stub="exercises/ex08_mbi.py", prepare=prepare,
                    blocked_modules=("mutext.mbi", "mutext.diagnose", "mutext.hide", "mutext.commands"))
