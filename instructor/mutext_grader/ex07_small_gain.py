r"""Grader of exercise ``ex07_small_gain``: the M-Delta loop and the small-gain theorem.

Questions (10 points):

(a) ``m_delta(m1, m2, k1, k2, r1, r2, K)``, 3 points: the system
    :math:`M = \mathcal F_\ell(P, K)` that the spring perturbation
    :math:`\Delta = \operatorname{diag}(\delta_1, \delta_2)` sees, compared
    channel by channel through frequency responses (relative tolerance 1e-4)
    for two drawn systems; each of the eight channels 3/8 point.
(b) ``small_gain(M)``, 2.5 points: ``[||M||_inf, omega_peak, 1/||M||_inf]``
    for two systems; per system 0.5 for the norm (1e-4), 0.5 for the peak
    frequency in rad/s (1 %), 0.25 for the margin (1e-4, counted only with
    the norm right).
(c) ``destabilizing_delta(M, omega)``, 2 points: a full complex
    :math:`\Delta` with :math:`\det(I - M(j\omega)\Delta) = 0` (to 1e-6,
    relative) and :math:`\bar\sigma(\Delta) = 1/\bar\sigma(M(j\omega))` (to
    1e-4), for two systems; a singular but larger :math:`\Delta` earns nothing
    (the SVD gives the least one exactly).
(d) ``structured_mu(M_re, M_im)``, 2.5 points: the peaks over a grid of the
    lower and upper bounds on :math:`\mu` for two complex ``1 x 1`` blocks,
    each against :func:`mutext.mu.mu_bounds` (exact here, ``2S + F <= 3``) to
    1e-3, for two systems.

The reference ``M`` is assembled here with numpy (closed-loop matrices of the
lower LFT written out; the reference solution takes python-control's
``StateSpace.lft`` instead); norms come from :func:`mutext.lti.hinf_norm`
(the solution uses SLICOT AB13DD through ``control.linfnorm``) and mu from
:mod:`mutext.mu` (the solution searches the one phase and the one scaling of
two blocks by itself).  ``tests/test_grading_ex07.py`` checks the reference
``M`` against the closed loop rebuilt with the perturbed springs.

Inputs are drawn per run from the generator the grader is given
(:func:`draw_system`): masses 0.5-3 kg, springs 200-800 and 100-600 N/m,
uncertainty sizes 5-40 %, and a collocated controller
:math:`K(s) = -(k_p + k_d s)/(1 + \tau s)` (positive real: the nominal loop is
stable) in a drawn state coordinate.  A draw is kept when the peak of
:math:`\bar\sigma(M)` is unique (any other local maximum at least 5 % lower),
and on the grid of (d) the peak of :math:`\bar\sigma` is 0.5 % above mu and
the peak of the spectral radius 0.25 % below it (2.5 tolerances), so the named shortcuts never
pass by chance.

Feedback names the mistake and never a reference value: the loop closed as
``u = -K y``, the uncertain channels without the factor ``r_i k_i`` (the
stretch instead of the force), ``w`` entering with the wrong sign, the
controller left out, the peak frequency in Hz, a norm from a grid that
missed the peak, the margin taken as the norm, ``det(I + M Delta) = 0``,
``Delta = u v^H`` (the transpose of what maps ``z`` to ``w``), a singular but
not minimal ``Delta`` (``I/lambda``), the frequency in Hz, ``sigma_max``
without scaling as the upper bound and the spectral radius as the lower.
"""
from __future__ import annotations

import functools
import math
import threading

import numpy as np

from mutext.lti import hinf_norm, ss
from mutext.response import frequency_grid
from .compare import as_array, build_ss, compare_responses, response, returned
from .core import Call, Exercise, Question

POINTS = {"a": 3.0, "b": 2.5, "c": 2.0, "d": 2.5}
RTOL_MODEL = 1e-4
RTOL_NORM = 1e-4
RTOL_FREQ = 0.01
SINGULAR_TOL = 1e-6
RTOL_DELTA = 1e-4
RTOL_MU = 1e-3
DISTINCT = 5e-3          # (d): the sigma_max peak above mu by this (relative) ...
DISTINCT_RHO = 2.5e-3    # ... and the spectral-radius peak below it by this (2.5 tolerances)
PEAK_GAP = 0.95          # (b): any other local maximum of sigma_max at most this times the peak
MAX_STATES = 15          # a returned M: three times the 5 states of a minimal one
N_GRID_D = 60
B_MATRIX = np.array([[1.0, 0.0], [-1.0, 1.0]])      # columns b_1 (k1, m1 - m2), b_2 (k2, m2 - ground)
INS, OUTS = ["w1", "w2"], ["z1", "z2"]


# ----------------------------------------------------------------------------
# the reference M (numpy, closed-loop matrices of the lower LFT)
# ----------------------------------------------------------------------------

def plant(m1, m2, k1, k2, r1, r2):
    """``(A, B, C)`` of ``P``: inputs ``[w1, w2, u]``, outputs ``[z1, z2, y]``, state ``[x; x']``, D = 0."""
    Mi = np.diag([1.0 / m1, 1.0 / m2])
    K0 = np.array([[k1, -k1], [-k1, k1 + k2]])
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-Mi @ K0, np.zeros((2, 2))]])
    B = np.vstack([np.zeros((2, 3)), Mi @ np.column_stack([-B_MATRIX, [0.0, 1.0]])])
    C = np.zeros((3, 4))
    C[:2, :2] = np.diag([r1 * k1, r2 * k2]) @ B_MATRIX.T
    C[2, 1] = 1.0
    return A, B, C


def closed_loop(m1, m2, k1, k2, r1, r2, K, sign=1.0, w_sign=1.0):
    """``M = F_l(P, sign * K)`` (``w_sign = -1``: ``w`` entering as ``+b_i w_i``), as a StateSpace."""
    A, B, C = plant(m1, m2, k1, k2, r1, r2)
    Ak, Bk, Ck, Dk = (np.atleast_2d(np.asarray(X, float)) for X in K)
    Ck, Dk = sign * Ck, sign * Dk
    B1, B2, C1, C2 = w_sign * B[:, :2], B[:, 2:], C[:2], C[2:]
    Acl = np.block([[A + B2 @ Dk @ C2, B2 @ Ck], [Bk @ C2, Ak]])
    Bcl = np.vstack([B1, np.zeros((Ak.shape[0], 2))])
    Ccl = np.hstack([C1, np.zeros((2, Ak.shape[0]))])
    return ss(Acl, Bcl, Ccl, np.zeros((2, 2)))


def perturbed_loop_poles(m1, m2, k1, k2, r1, r2, K, delta):
    """Poles of the loop rebuilt with the springs ``k_i (1 + r_i delta_i)`` (no LFT): a check of ``M``."""
    A, B, C = plant(m1, m2, k1 * (1 + r1 * delta[0]), k2 * (1 + r2 * delta[1]), 0.0, 0.0)
    Ak, Bk, Ck, Dk = (np.atleast_2d(np.asarray(X, float)) for X in K)
    B2, C2 = B[:, 2:], C[2:]
    return np.linalg.eigvals(np.block([[A + B2 @ Dk @ C2, B2 @ Ck], [Bk @ C2, Ak]]))


def controller(kp, kd, tau, g):
    r"""``(A, B, C, D)`` of :math:`K(s) = -(k_p + k_d s)/(1 + \tau s)` with the state scaled by ``g``."""
    return ([[-1.0 / tau]], [[g]], [[-(kp - kd / tau) / (tau * g)]], [[-kd / tau]])


def _sigma(M, w):
    H = response(M, w)[0]
    return np.array([np.linalg.svd(H[:, :, k], compute_uv=False)[0] for k in range(len(w))])


def d_grid(M):
    """The ``N_GRID_D`` frequencies [rad/s] of (d): log-spaced around the loop's poles."""
    return frequency_grid(n=N_GRID_D, poles=np.linalg.eigvals(np.asarray(M.A, float)), margin=(5.0, 5.0))


def _structure():
    from mutext.mu import BlockStructure
    return BlockStructure.from_spec([[1, 0], [1, 0]])


_LOCK = threading.RLock()


@functools.lru_cache(maxsize=64)
def _mu_cached(key):
    from mutext.mu import mu_bounds
    Ms = np.array(key[1]).reshape(key[0])
    lo, up = [], []
    for Mj in Ms:
        b = mu_bounds(Mj, _structure(), method="osborne")
        lo.append(b.lower.value)
        up.append(b.upper.value)
    return float(max(lo)), float(max(up))


def mu_peaks(Ms):
    """Peaks over the grid of mutext's lower and upper bounds (two complex scalar blocks)."""
    Ms = np.asarray(Ms, complex)
    with _LOCK:
        return _mu_cached((Ms.shape, tuple(Ms.ravel().tolist())))


def _local_maxima(s):
    return [k for k in range(1, len(s) - 1) if s[k] >= s[k - 1] and s[k] >= s[k + 1]]


def draw_system(rng):
    """``(params, K)`` of one drawn system whose ``M`` has a unique peak and bounds apart (see module doc)."""
    for _ in range(200):
        m1, m2 = (float(f"{rng.uniform(0.5, 3.0):.4g}") for _ in range(2))
        k1, k2 = float(f"{rng.uniform(200, 800):.4g}"), float(f"{rng.uniform(100, 600):.4g}")
        r1, r2 = (float(f"{rng.uniform(0.05, 0.4):.3g}") for _ in range(2))
        Mm = np.diag([m1, m2])
        K0 = np.array([[k1, -k1], [-k1, k1 + k2]])
        wn = np.sqrt(np.linalg.eigvals(np.linalg.solve(Mm, K0)).real)
        kp = rng.uniform(0.0, 0.3) * k2
        kd = rng.uniform(0.1, 0.6) * math.sqrt(k2 * m2)
        tau = 1.0 / (rng.uniform(5.0, 15.0) * wn.max())
        K = controller(kp, kd, tau, float(rng.choice([-1, 1]) * rng.uniform(0.5, 5.0)))
        p = dict(m1=m1, m2=m2, k1=k1, k2=k2, r1=r1, r2=r2)
        M = closed_loop(**p, K=K)
        if np.linalg.eigvals(np.asarray(M.A, float)).real.max() >= -1e-6:
            continue
        w = frequency_grid(n=800, poles=np.linalg.eigvals(np.asarray(M.A, float)), margin=(5.0, 5.0))
        s = _sigma(M, w)
        peaks = sorted((s[k] for k in _local_maxima(s)), reverse=True)
        if not peaks or (len(peaks) > 1 and peaks[1] > PEAK_GAP * peaks[0]):
            continue
        Ms = _response_stack(M, d_grid(M))
        sig = max(np.linalg.svd(Mj, compute_uv=False)[0] for Mj in Ms)
        rho = max(np.abs(np.linalg.eigvals(Mj)).max() for Mj in Ms)
        if sig <= (1 + DISTINCT) / (1 - DISTINCT_RHO) * rho:      # rho <= mu <= sigma: no room for both
            continue
        lo, up = mu_peaks(Ms)
        if sig > (1 + DISTINCT) * up and rho < (1 - DISTINCT_RHO) * lo and abs(up - lo) <= 1e-4 * up:
            return p, K
    raise RuntimeError("no suitable system drawn")   # pragma: no cover


def _response_stack(M, w):
    return np.moveaxis(response(M, w)[0], 2, 0)


def _ss_arg(S):
    return {"__ss__": [np.asarray(getattr(S, X), float).tolist() for X in "ABCD"]}


def _draw(rng):
    return [draw_system(rng) for _ in range(2)]


def prepare(rng=None):
    """mu bounds of (d) (the same draws as :func:`questions` with an equal generator)."""
    if rng is not None:
        for p, K in _draw(rng):
            M = closed_loop(**p, K=K)
            mu_peaks(_response_stack(M, d_grid(M)))


# ----------------------------------------------------------------------------
# (a)
# ----------------------------------------------------------------------------

def _alternatives(p, K):
    r1k1, r2k2 = p["r1"] * p["k1"], p["r2"] * p["k2"]
    open_loop = closed_loop(**p, K=([[-1.0]], [[0.0]], [[0.0]], [[0.0]]))
    return [
        (closed_loop(**p, K=K, sign=-1.0), "the loop is closed as u = -K y; F_l(P, K) closes u = +K y"),
        (closed_loop(**p, K=K, w_sign=-1.0), "w enters with the wrong sign: the forces on the masses are "
                                            "-b_i w_i (w pushes back along its spring)"),
        (open_loop, "this is the open loop (the controller is left out): M = F_l(P, K) includes the loop "
                    "u = K y"),
        (ss(*(np.asarray(X) for X in (lambda S: (S.A, S.B, np.diag([1 / r1k1, 1 / r2k2]) @ np.asarray(S.C),
                                                  S.D))(closed_loop(**p, K=K)))),
         "z_i is the stretch of spring i; the convention is the force r_i k_i times the stretch"),
    ]


def _check_a(outcomes, calls):
    per = POINTS["a"] / (4 * len(calls))
    score, fb = 0.0, []
    for call, tag, value in returned(outcomes, calls, fb):
        if isinstance(value, dict) and len(value.get("A") or []) > MAX_STATES:
            fb.append(f"{tag} the model has more than {MAX_STATES} states (a minimal M has 5): not evaluated")
            continue
        S, err = build_ss(value, "m_delta()")
        if err:
            fb.append(f"{tag} {err}")
            continue
        if (S.ninputs, S.noutputs) != (2, 2):
            fb.append(f"{tag} expected 2 inputs [w1, w2] and 2 outputs [z1, z2], got {S.ninputs} inputs and "
                      f"{S.noutputs} outputs")
            continue
        ref = call.ref
        w = call.grid
        Gr = response(ref, w)[0]
        Gs, err = response(S, w)
        if err:
            fb.append(f"{tag} {err}")
            continue
        atol = 1e-9 * np.abs(Gr).max()
        checks = compare_responses(Gs, Gr, w, INS, OUTS, rtol=RTOL_MODEL, atol=atol)
        n_ok = sum(c.ok for c in checks)
        score += per * n_ok
        if n_ok == len(checks):
            continue
        named = None
        for alt, text in call.alternatives:
            Ga = response(alt, w)[0]
            if np.all(np.abs(Gs - Ga) <= RTOL_MODEL * np.abs(Ga) + atol):
                named = text
                break
        if named is None:
            bad = [c for c in checks if not c.ok]
            named = (f"{len(bad)} of 4 channels differ ({', '.join(c.inp + ' -> ' + c.out for c in bad)}); "
                     "check the plant's B and C and the sign of the loop")
            if np.all(np.abs(Gs + Gr) <= RTOL_MODEL * np.abs(Gr) + atol):
                named = "M has the opposite sign: check the sign of w's forces (-b_i w_i) and of z"
            elif np.all(np.abs(Gs[::-1, ::-1] - Gr) <= RTOL_MODEL * np.abs(Gr) + atol):
                named = "the channels are in the order [w2, w1] -> [z2, z1]; use [w1, w2] and [z1, z2]"
        fb.append(f"{tag} {named}")
    if not fb:
        fb = ["correct: all channels of both systems agree"]
    return score, fb


# ----------------------------------------------------------------------------
# (b)
# ----------------------------------------------------------------------------

def _check_b(outcomes, calls):
    per = POINTS["b"] / len(calls)
    score, fb = 0.0, []
    for call, tag, x in returned(outcomes, calls, fb, as_array, "small_gain()"):
        x = x.ravel()
        if x.size != 3 or not np.all(np.isfinite(x)):
            fb.append(f"{tag} expected three finite numbers [norm, omega_peak, margin], got {x.size}")
            continue
        norm, wpk, margin = (float(v) for v in x)
        gref, wref = call.ref
        norm_ok = abs(norm - gref) <= RTOL_NORM * gref
        if norm_ok:
            score += 0.4 * per
        elif norm < gref:
            fb.append(f"{tag} the norm is too low: a frequency grid misses the top of the peak (use the "
                      "Hamiltonian test, or refine around the grid's maximum)")
        else:
            fb.append(f"{tag} the norm is too high (is it the largest singular value, not the sum or the "
                      "Frobenius norm?)")
        if abs(wpk - wref) <= RTOL_FREQ * wref:
            score += 0.4 * per
        elif abs(wpk * 2 * math.pi - wref) <= RTOL_FREQ * wref:
            fb.append(f"{tag} the peak frequency is in Hz; rad/s is asked (omega = 2 pi f)")
        else:
            fb.append(f"{tag} the peak frequency is not within {RTOL_FREQ:.0%} of where sigma_max(M) peaks")
        if norm_ok and abs(margin - 1.0 / gref) <= RTOL_NORM / gref:
            score += 0.2 * per
        elif norm_ok and abs(margin - gref) <= RTOL_NORM * gref:
            fb.append(f"{tag} the margin is the norm itself; small gain gives the margin 1/||M||_inf")
        elif norm_ok:
            fb.append(f"{tag} the margin is not 1/||M||_inf")
    if not fb:
        fb = ["correct: norms, peak frequencies and margins"]
    return score, fb


# ----------------------------------------------------------------------------
# (c)
# ----------------------------------------------------------------------------

def _singular(Mj, Delta):
    E = np.eye(2) - Mj @ Delta
    s = np.linalg.svd(E, compute_uv=False)
    return s[-1] / (1 + np.linalg.svd(Mj @ Delta, compute_uv=False)[0])


def _check_c(outcomes, calls):
    per = POINTS["c"] / len(calls)
    score, fb = 0.0, []
    for call, tag, x in returned(outcomes, calls, fb, as_array, "destabilizing_delta()"):
        if x.size != 8:
            fb.append(f"{tag} expected (Delta.real, Delta.imag), an array of shape (2, 2, 2), got {x.size} numbers")
            continue
        if not np.all(np.isfinite(x)):
            fb.append(f"{tag} Delta holds NaN or infinite entries")
            continue
        x = x.reshape(2, 2, 2)
        D = x[0] + 1j * x[1]
        Mj, smax = call.Mj, call.smax
        if _singular(Mj, D) <= SINGULAR_TOL:
            if abs(np.linalg.svd(D, compute_uv=False)[0] * smax - 1) <= RTOL_DELTA:
                score += per
                continue
            lam = np.abs(np.linalg.eigvals(Mj)).max()
            if abs(np.linalg.svd(D, compute_uv=False)[0] * lam - 1) <= RTOL_DELTA:
                fb.append(f"{tag} I - M Delta is singular but Delta is I/lambda (an eigenvalue of M): its norm "
                          "is not minimal; the SVD gives the least one, v_1 u_1^H / sigma_1")
            else:
                fb.append(f"{tag} I - M Delta is singular but the norm of Delta is not minimal "
                          "(the least is 1/sigma_max(M(j omega)))")
            continue
        if _singular(-Mj, D) <= SINGULAR_TOL:
            fb.append(f"{tag} this Delta makes I + M Delta singular; the loop w = Delta z gives det(I - M Delta) = 0")
        elif _singular(Mj, D.T) <= SINGULAR_TOL or _singular(Mj, D.conj().T) <= SINGULAR_TOL:
            fb.append(f"{tag} Delta is transposed: it maps z to w, so Delta = v_1 u_1^H / sigma_1 (not u_1 v_1^H)")
        elif any(_singular(Mw, D) <= SINGULAR_TOL for Mw in call.hz):
            fb.append(f"{tag} Delta is right for M at another frequency: omega is in rad/s (s = j omega), not Hz")
        else:
            fb.append(f"{tag} I - M(j omega) Delta is not singular")
    if not fb:
        fb = ["correct: both perturbations are destabilising and of least norm"]
    return score, fb


# ----------------------------------------------------------------------------
# (d)
# ----------------------------------------------------------------------------

def _check_d(outcomes, calls):
    per = POINTS["d"] / len(calls)
    score, fb = 0.0, []
    for call, tag, x in returned(outcomes, calls, fb, as_array, "structured_mu()"):
        x = x.ravel()
        if x.size != 2 or not np.all(np.isfinite(x)):
            fb.append(f"{tag} expected two finite numbers [lower, upper], got {x.size}")
            continue
        lo, up = float(x[0]), float(x[1])
        ref = call.ref
        for name, v, short, short_text in (
                ("lower", lo, call.rho, "the peak of the spectral radius rho(M): search the diagonal unitary U "
                                        "(one phase) for the largest rho(M U)"),
                ("upper", up, call.sig, "the peak of sigma_max(M) without scaling (the full-block bound); "
                                        "minimise sigma_max(D M D^-1) over D")):
            if abs(v - ref) <= RTOL_MU * ref:
                score += per / 2
            elif abs(v - short) <= RTOL_MU * short:
                fb.append(f"{tag} the {name} bound is {short_text}")
            else:
                fb.append(f"{tag} the {name} bound is not within {RTOL_MU:.0e} of mu "
                          f"({'too high' if v > ref else 'too low'})")
    if not fb:
        fb = ["correct: both bounds meet mu"]
    return score, fb


def questions(rng=None):
    """The four questions, drawn from ``rng``; the answers are computed here, not in the child."""
    rng = np.random.default_rng() if rng is None else rng
    systems = _draw(rng)
    a_calls, b_calls, c_calls, d_calls = [], [], [], []
    for n, (p, K) in enumerate(systems):
        label = f"system {n + 1} of {len(systems)}"
        M = closed_loop(**p, K=K)
        call = Call(label, [p["m1"], p["m2"], p["k1"], p["k2"], p["r1"], p["r2"],
                            {"__ss__": [np.asarray(X, float).tolist() for X in K]}])
        call.ref = M
        call.grid = frequency_grid(n=40, poles=np.linalg.eigvals(np.asarray(M.A, float)), margin=(10.0, 10.0))
        call.alternatives = _alternatives(p, K)
        a_calls.append(call)
        h = hinf_norm(M)
        call = Call(label, [_ss_arg(M)])
        call.ref = (float(h.value), float(h.frequency))
        b_calls.append(call)
        call = Call(label, [_ss_arg(M), float(h.frequency)])
        call.Mj = response(M, [h.frequency])[0][:, :, 0]
        call.smax = float(np.linalg.svd(call.Mj, compute_uv=False)[0])
        call.hz = [response(M, [h.frequency * f])[0][:, :, 0] for f in (2 * math.pi, 1 / (2 * math.pi))]
        c_calls.append(call)
        Ms = _response_stack(M, d_grid(M))
        call = Call(label, [Ms.real.tolist(), Ms.imag.tolist()])
        call.Ms = Ms
        call.sig = float(max(np.linalg.svd(Mj, compute_uv=False)[0] for Mj in Ms))
        call.rho = float(max(np.abs(np.linalg.eigvals(Mj)).max() for Mj in Ms))
        d_calls.append(call)

    def check_d(oc):
        for call in d_calls:
            call.ref = mu_peaks(call.Ms)[1]
        return _check_d(oc, d_calls)

    return [
        Question("a", "m_delta", "the M of the M-Delta loop", POINTS["a"], "ss", a_calls,
                 lambda oc: _check_a(oc, a_calls)),
        Question("b", "small_gain", "H-infinity norm, peak frequency and small-gain margin", POINTS["b"], "array",
                 b_calls, lambda oc: _check_b(oc, b_calls)),
        Question("c", "destabilizing_delta", "least destabilising full complex Delta", POINTS["c"], "array",
                 c_calls, lambda oc: _check_c(oc, c_calls)),
        Question("d", "structured_mu", "mu bounds for the diagonal structure", POINTS["d"], "array", d_calls,
                 check_d),
    ]


EXERCISE = Exercise("ex07_small_gain", "The M-Delta loop: small gain, destabilising Delta, structured mu",
                    questions, stub="exercises/ex07_small_gain.py", prepare=prepare,
                    blocked_modules=("mutext.mu", "mutext.uncertain", "mutext.dk", "mutext.mbi"))
