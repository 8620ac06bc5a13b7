r"""Grader of exercise ``ex02_mu``: the structured singular value with numpy, scipy or cvxpy.

Questions (10 points):

(a1) ``mu_full(M_re, M_im)``, 1 point: :math:`\mu` for one full complex
     block, the largest singular value (four matrices, 0.25 points each).
(a2) ``mu_scalar_blocks_upper(M_re, M_im)``, 2 points: the D-scaling upper
     bound :math:`\min_D \bar\sigma(DMD^{-1})` for ``n`` complex ``1 x 1``
     blocks (four matrices, 0.5 points each).
(b)  ``destabilizing_delta(M_re, M_im)``, 2 points: a diagonal complex
     :math:`\Delta` with :math:`\det(I - M\Delta) = 0`; full points when
     :math:`1/\bar\sigma(\Delta)` is within 2 % of the lower bound of
     :func:`mutext.mu.mu_lower`, half of them for any such :math:`\Delta`
     (three matrices).
(c)  ``uncertain_spring_lft(m, k, rel)``, 3 points: a mass-spring model
     with the stiffness :math:`k(1 + \text{rel}\,\delta)` as an upper LFT, inputs
     ``[w, f]``, outputs ``[z, x]``.  The grader closes ``w = delta z`` for
     several ``delta`` in ``[-1, 1]`` and compares with the directly built
     model at complex frequencies, so any valid scaling of ``w`` and ``z``
     is accepted (two parameter sets, 1.5 points each).
(d)  ``mu_peak(M_re, M_im)``, 2 points: the peak over frequency of the
     upper bound of (a2) for a frequency response of shape ``(N, n, n)``
     (two responses, 1 point each).

Complex matrices are passed as their real and imaginary parts (the channel
to the submission carries real numbers only); (b) returns
``(Delta.real, Delta.imag)``.  The references are computed with
:mod:`mutext.mu` (``mu_upper(..., method="osborne")``, exact for full and
``1 x 1`` blocks, and ``mu_lower``); submissions may not import
:mod:`mutext.mu`, :mod:`mutext.uncertain` or :mod:`mutext.dk`.  Feedback
names the usual mistakes: the spectral radius or the Frobenius norm instead
of the largest singular value, no D-scaling, ``D M D`` instead of
``D M D^-1``, an unconverged optimisation, a non-diagonal (full-block)
perturbation, ``I + M Delta`` instead of ``I - M Delta``, an LFT that closes
with the wrong sign or lacks the size ``rel``, the channels in lower-LFT
order.
"""
from __future__ import annotations

import functools
import threading

import numpy as np
from scipy.optimize import minimize

from .compare import as_array, fmt, returned
from .core import Call, Exercise, Question

POINTS = {"a1": 1.0, "a2": 2.0, "b": 2.0, "c": 3.0, "d": 2.0}
RTOL_MU = 1e-3          # (a), (d): relative tolerance on mu
LOWER_FRACTION = 0.98   # (b): 1/sigma_max(Delta) must reach this fraction of the reference lower bound
SINGULAR_TOL = 1e-6     # (b): |det(I - M Delta)| / prod(1 + sigma_i(M Delta))
RTOL_LFT = 1e-6         # (c): closed-loop frequency responses
DELTAS = (-1.0, -0.4, 0.0, 0.6, 1.0)

#: test matrices of (a) and (b): label -> M
MATRICES = {
    "M = [[2, 2], [-1, -1]] (Skogestad & Postlethwaite, example 8.5)": np.array([[2.0, 2.0], [-1.0, -1.0]]),
    "complex 2x2 M": np.array([[1.0 + 1.0j, 4.0 - 2.0j], [0.2 + 0.1j, 1.5 - 1.0j]]),
    "complex 3x3 M": np.array([[0.3 - 1.2j, 2.0 + 0.5j, -0.4 + 0.0j],
                               [0.1 + 0.2j, -0.7 + 0.9j, 3.0 - 1.0j],
                               [1.5 + 0.0j, 0.05 - 0.3j, 0.6 + 0.4j]]),
    "badly scaled real 3x3 M": np.array([[1.0, 20.0, 0.0], [0.05, 1.0, 10.0], [0.5, 0.1, -2.0]]),
}
B_LABELS = list(MATRICES)[:3]

#: (c): (m [kg], k [N/m], rel)
SPRINGS = [(2.0, 800.0, 0.2), (0.5, 3.0e4, 0.35)]


def _split(M):
    M = np.asarray(M, dtype=complex)
    return [M.real.tolist(), M.imag.tolist()]


# ----------------------------------------------------------------------------
# references (mutext.mu)
# ----------------------------------------------------------------------------

def _structure(n):
    from mutext.mu import BlockStructure
    return BlockStructure.from_spec([[1, 0]] * n)


_LOCK = threading.Lock()


@functools.lru_cache(maxsize=256)
def _upper_cached(key):
    from mutext.mu import mu_upper
    M = np.array(key[1]).reshape(key[0])
    return float(mu_upper(M, _structure(M.shape[0]), method="osborne").value)


def mu_upper_ref(M):
    """D-scaling upper bound (``n`` complex ``1 x 1`` blocks) from :func:`mutext.mu.mu_upper`."""
    M = np.asarray(M, dtype=complex)
    with _LOCK:
        return _upper_cached((M.shape, tuple(M.ravel().tolist())))


@functools.lru_cache(maxsize=16)
def _lower_cached(key):
    from mutext.mu import mu_bounds
    M = np.array(key[1]).reshape(key[0])
    return float(mu_bounds(M, _structure(M.shape[0]), method="osborne").lower.value)


def mu_lower_ref(M):
    """Lower bound (``n`` complex ``1 x 1`` blocks) from :func:`mutext.mu.mu_bounds`."""
    M = np.asarray(M, dtype=complex)
    with _LOCK:
        return _lower_cached((M.shape, tuple(M.ravel().tolist())))


SWEEP_W = np.logspace(-1, 1.5, 40)     # rad/s


def sweep(which):
    """Frequency response ``(N, n, n)`` of the test systems of (d)."""
    s = 1j * SWEEP_W
    if which == 0:
        den = s**2 + 0.3 * s + 4.0
        return np.stack([np.array([[2.0 / (si + 1.0), 3.0 * si / di], [-0.5 / (si + 0.5), (si + 1.0) / di]])
                         for si, di in zip(s, den)])
    A = np.array([[-0.2, 3.0, 0.0], [-3.0, -0.2, 0.0], [0.0, 0.0, -1.5]])
    B = np.array([[1.0, 0.0, 0.5], [0.0, 2.0, 0.0], [0.3, 0.0, 1.0]])
    C = np.array([[0.0, 1.0, 0.2], [1.0, 0.0, 0.0], [0.1, 0.5, 2.0]])
    return np.stack([C @ np.linalg.solve(si * np.eye(3) - A, B) for si in s])


def peak_ref(which):
    return max(mu_upper_ref(M) for M in sweep(which))


def prepare(rng=None):
    """Reference bounds of all calls, while the child runs."""
    for M in MATRICES.values():
        mu_upper_ref(M)
    for lab in B_LABELS:
        mu_lower_ref(MATRICES[lab])
    for i in (0, 1):
        peak_ref(i)


# ----------------------------------------------------------------------------
# helpers
# ----------------------------------------------------------------------------


def _close(x, ref, rtol=RTOL_MU):
    return bool(np.isfinite(x) and abs(x - ref) <= rtol * max(abs(ref), 1e-12))


def _sv(M):
    return np.linalg.svd(M, compute_uv=False)


def dmd_value(M):
    """``min sigma_max(D M D)`` with the last entry of ``D`` fixed to 1 (the mistake ``D M D``)."""
    M = np.asarray(M, dtype=complex)
    n = M.shape[0]

    def f(x):
        d = np.exp(np.clip(np.concatenate([x, [0.0]]), -30, 30))
        return np.log(_sv(d[:, None] * M * d[None, :])[0])

    r = minimize(f, np.zeros(n - 1), method="Nelder-Mead",
                 options={"xatol": 1e-10, "fatol": 1e-13, "maxiter": 20000, "maxfev": 20000})
    return float(np.exp(r.fun))


def _mistakes_scalar(M):
    """``(value, text)`` of the usual wrong answers for ``n`` complex scalar blocks."""
    sv = _sv(M)
    return [
        (sv[0], "no D-scaling: this is sigma_max(M), mu for one full block; minimise sigma_max(D M D^-1) "
                "over positive diagonal D"),
        (max(abs(np.linalg.eigvals(M))), "returned the spectral radius max|eig(M)|, a lower bound on mu "
                                         "(not the D-scaling upper bound)"),
        (dmd_value(M), "D applied as D M D instead of D M D^-1 (the scaling must be a similarity)"),
        (mu_upper_ref(M.real) if M.shape[0] > 0 else np.nan,
         "this is the bound of the real part of M only: build M = M_re + 1j*M_im"),
    ]


def _mistakes_full(M):
    sv = _sv(M)
    return [
        (max(abs(np.linalg.eigvals(M))), "returned the spectral radius max|eig(M)|, not the largest singular "
                                         "value (the spectral radius is mu of a repeated scalar block delta I)"),
        (np.linalg.norm(M, "fro"), "returned the Frobenius norm, not the largest singular value"),
        (sv[-1], "returned the smallest singular value, not the largest"),
        (sv[0] ** 2, "returned sigma_max^2 (the largest eigenvalue of M^H M): take the square root"),
        (_sv(M.real)[0], "this is sigma_max of the real part of M only: build M = M_re + 1j*M_im"),
    ]


def _diagnose(x, ref, mistakes, sigma=None):
    texts = [text for val, text in mistakes if _close(x, val) and not _close(val, ref)]
    if texts:
        return "; or ".join(texts)      # e.g. rho(M) and min sigma(D M D) coincide for a rank-one M
    if not np.isfinite(x):
        return "the value is not finite"
    if sigma is not None and ref < x < sigma:
        return (f"expected {fmt(ref)}, got {fmt(x)}: between the optimum and sigma_max(M), so the minimisation over "
                "D did not converge (tighten the tolerance, or bisect on the LMI M^H X M - beta^2 X <= 0)")
    return f"expected {fmt(ref)}, got {fmt(x)}"


def _correct(fb, n_ok, n, text):
    if n_ok == n:
        fb.insert(0, f"correct: {text}")
    return fb


# ----------------------------------------------------------------------------
# (a) mu of one full block and the D-scaling upper bound
# ----------------------------------------------------------------------------

def _check_a(outcomes, calls, which):
    qid = "a1" if which == "full" else "a2"
    per = POINTS[qid] / len(calls)
    score, fb, n_ok = 0.0, [], 0
    for call, tag, value in returned(outcomes, calls, fb):
        x = float(value)
        M = MATRICES[call.label]
        if which == "full":
            ref, mistakes = float(_sv(M)[0]), _mistakes_full(M)
        else:
            ref, mistakes = mu_upper_ref(M), _mistakes_scalar(M)
        if _close(x, ref):
            score += per
            n_ok += 1
            continue
        sigma = None if which == "full" else float(_sv(M)[0])
        fb.append(f"{tag} {_diagnose(x, ref, mistakes, sigma)}")
    what = "sigma_max(M) of every matrix" if which == "full" else "the D-scaling bound of every matrix"
    return score, _correct(fb, n_ok, len(calls), what)


# ----------------------------------------------------------------------------
# (b) destabilising perturbation
# ----------------------------------------------------------------------------

def _residual(M, Delta):
    """``|det(I - M Delta)|`` relative to ``prod(1 + sigma_i(M Delta))``."""
    MD = M @ Delta
    return float(abs(np.linalg.det(np.eye(M.shape[0]) - MD)) / np.prod(1.0 + _sv(MD)))


def _check_b(outcomes, calls):
    per = POINTS["b"] / len(calls)
    score, fb, n_ok = 0.0, [], 0
    for call, tag, X in returned(outcomes, calls, fb, as_array, "destabilizing_delta()"):
        M = MATRICES[call.label]
        n = M.shape[0]
        if X.shape == (2, n):
            X = np.stack([np.diag(X[0]), np.diag(X[1])])
        if X.shape != (2, n, n):
            fb.append(f"{tag} return the pair (Delta.real, Delta.imag) of the {n}x{n} diagonal Delta "
                      f"(an array of shape (2, {n}, {n})), got shape {X.shape}")
            continue
        Delta = X[0] + 1j * X[1]
        if not np.all(np.isfinite(Delta)):
            fb.append(f"{tag} Delta has entries that are not finite")
            continue
        off = Delta - np.diag(np.diag(Delta))
        if np.abs(off).max() > 1e-9 * max(np.abs(Delta).max(), 1e-300):
            extra = ""
            if _residual(M, Delta) < SINGULAR_TOL:
                extra = ("; it does make I - M Delta singular, like the rank-one v u^H / sigma_1 from the SVD, "
                         "but that perturbs one full block")
            fb.append(f"{tag} Delta is not diagonal: with n scalar blocks Delta = diag(delta_1, ..., delta_n)"
                      f"{extra}")
            continue
        if np.abs(Delta).max() == 0:
            fb.append(f"{tag} Delta is zero: I - M Delta = I is not singular")
            continue
        res = _residual(M, Delta)
        if res > SINGULAR_TOL:
            if _residual(M, -Delta) < SINGULAR_TOL:
                msg = "I + M Delta is singular, not I - M Delta: change the sign of Delta"
            elif np.all(np.abs(np.diag(Delta)) > 0) and _residual(M, np.diag(1.0 / np.diag(Delta))) < SINGULAR_TOL:
                msg = ("I - M Delta^-1 is singular, not I - M Delta: divide by the eigenvalue lambda of M U "
                       "(Delta = U / lambda) instead of multiplying")
            else:
                msg = (f"I - M Delta is not singular: |det(I - M Delta)| = "
                       f"{fmt(abs(np.linalg.det(np.eye(n) - M @ Delta)))} (relative {res:.1e}, at most "
                       f"{SINGULAR_TOL:g} is accepted)")
            fb.append(f"{tag} {msg}")
            continue
        mu_d = 1.0 / float(_sv(Delta)[0])
        lower = mu_lower_ref(M)
        if mu_d >= LOWER_FRACTION * lower:
            score += per
            n_ok += 1
            continue
        score += per / 2
        fb.append(f"{tag} half points: Delta destabilises, but 1/sigma_max(Delta) = {fmt(mu_d)} while a diagonal "
                  f"Delta with 1/sigma_max = {fmt(lower)} exists (mu >= {fmt(lower)}): maximise rho(M U) over "
                  "diagonal unitary U")
    return score, _correct(fb, n_ok, len(calls), "every Delta is diagonal, makes I - M Delta singular and is "
                                                 "as small as mutext's lower bound")


# ----------------------------------------------------------------------------
# (c) uncertain spring as an upper LFT
# ----------------------------------------------------------------------------

def _points(m, k):
    wn = np.sqrt(k / m)
    return wn * np.array([0.1 + 0.3j, 0.5 + 1.2j, 0.05 + 2.5j, 0.02 + 0.7j, 1.0 + 0.1j])


def _response(A, B, C, D, s):
    n = A.shape[0]
    if n == 0:
        return D.astype(complex)
    return C @ np.linalg.solve(s * np.eye(n) - A, B) + D


def _closed(P, delta):
    """``F_u(P, delta) = P22 + P21 delta (1 - P11 delta)^-1 P12`` (scalar channels)."""
    return P[1, 1] + P[1, 0] * delta * P[0, 1] / (1.0 - P[0, 0] * delta)


def _k_eff(Ps, s, m, delta):
    """Stiffness ``1/G - m s^2`` of the closed loop at each point (NaN where it is singular)."""
    with np.errstate(all="ignore"):
        G = np.array([_closed(P, delta) for P in Ps])
        return 1.0 / G - m * s**2


def _lft_error(Ps, s, m, k, rel):
    """Largest relative error of the closed LFT over the sampled deltas."""
    worst = 0.0
    with np.errstate(all="ignore"):
        for delta in DELTAS:
            G = np.array([_closed(P, delta) for P in Ps])
            ref = 1.0 / (m * s**2 + k * (1 + rel * delta))
            e = np.max(np.abs(G - ref) / np.abs(ref))
            worst = max(worst, e if np.isfinite(e) else np.inf)
    return worst


def _diagnose_lft(Ps, s, m, k, rel):
    perms = [((0, 1), (0, 1), None),
             ((1, 0), (1, 0), "the channels are in lower-LFT order (inputs [f, w], outputs [x, z]): for an upper "
                              "LFT the uncertainty channel comes first, inputs [w, f] and outputs [z, x]"),
             ((0, 1), (1, 0), "the inputs are in the wrong order: [w, f] is expected"),
             ((1, 0), (0, 1), "the outputs are in the wrong order: [z, x] is expected")]
    for rows, cols, text in perms[1:]:
        Q = [P[np.ix_(rows, cols)] for P in Ps]
        if _lft_error(Q, s, m, k, rel) <= RTOL_LFT:
            return text
    nominal = np.array([P[1, 1] for P in Ps])
    ref0 = 1.0 / (m * s**2 + k)
    if np.max(np.abs(nominal - ref0) / np.abs(ref0)) > RTOL_LFT:
        return ("the nominal model (delta = 0, the channel f -> x) is not 1/(m s^2 + k): "
                "check the mass, the stiffness and that x is a displacement in m")
    ks = {d: _k_eff(Ps, s, m, d) for d in DELTAS}
    if not all(np.all(np.isfinite(v)) for v in ks.values()):
        return "closing w = delta z makes the loop singular for some delta in [-1, 1]"
    if any(np.max(np.abs(v - v.mean())) > 1e-6 * k for v in ks.values()):
        return ("the closed loop is not a mass-spring 1/(m s^2 + k(delta)) for every delta: the uncertainty must "
                "enter as a spring force proportional to x")
    kd = {d: float(v.mean().real) for d, v in ks.items()}
    c = [(kd[d] / k - 1.0) / d for d in DELTAS if d != 0]
    if max(c) - min(c) > 1e-6 * max(1.0, abs(np.mean(c))):
        return ("k depends nonlinearly on delta: for k (1 + rel delta) the feedthrough P11 (w -> z) must be zero")
    c = float(np.mean(c))
    if abs(c + rel) <= 1e-6 * rel:
        return ("the LFT closes with the wrong sign: w = delta z gives k (1 - rel delta); with z = rel k x the "
                "force -w (not +w) acts on the mass")
    if abs(c - 1.0) <= 1e-6:
        return f"the size rel is missing: your k varies as k (1 + delta), expected k (1 + {rel:g} delta)"
    return f"closing w = delta z gives k (1 + {c:.4g} delta), expected k (1 + {rel:g} delta)"


def _check_c(outcomes, calls):
    per = POINTS["c"] / len(calls)
    score, fb, n_ok = 0.0, [], 0
    for call, tag, value in returned(outcomes, calls, fb):
        v = value
        try:
            A, B, C, D = (np.atleast_2d(np.asarray(v[x], dtype=float)) for x in "ABCD")
        except Exception as exc:   # noqa: BLE001
            fb.append(f"{tag} the returned matrices do not form a state-space model ({exc})")
            continue
        if v.get("dt") not in (None, 0, 0.0):
            fb.append(f"{tag} the model is discrete-time; a continuous-time model is expected")
            continue
        if len(v["A"]) == 0:
            A = np.zeros((0, 0))
            B = np.zeros((0, D.shape[1]))
            C = np.zeros((D.shape[0], 0))
        if D.shape != (2, 2):
            fb.append(f"{tag} P must have 2 inputs [w, f] and 2 outputs [z, x], got {D.shape[1]} inputs and "
                      f"{D.shape[0]} outputs")
            continue
        m, k, rel = call.args
        s = _points(m, k)
        try:
            Ps = [_response(A, B, C, D, si) for si in s]
        except Exception as exc:   # noqa: BLE001
            fb.append(f"{tag} the frequency response could not be computed ({exc})")
            continue
        if _lft_error(Ps, s, m, k, rel) <= RTOL_LFT:
            score += per
            n_ok += 1
            continue
        fb.append(f"{tag} {_diagnose_lft(Ps, s, m, k, rel)}")
    return score, _correct(fb, n_ok, len(calls), "closing w = delta z gives m x'' + k (1 + rel delta) x = f for "
                                                 "every delta tried")


# ----------------------------------------------------------------------------
# (d) peak over frequency
# ----------------------------------------------------------------------------

def _check_d(outcomes, calls):
    per = POINTS["d"] / len(calls)
    score, fb, n_ok = 0.0, [], 0
    for i, (call, oc) in enumerate(zip(calls, outcomes)):
        tag = f"[{call.label}]"
        if not oc["ok"]:
            fb.append(f"{tag} {oc['error']}")
            continue
        x = float(oc["value"])
        Ms = sweep(i)
        ref = peak_ref(i)
        if _close(x, ref):
            score += per
            n_ok += 1
            continue
        mistakes = [
            (max(_sv(M)[0] for M in Ms), "no D-scaling: this is the peak of sigma_max(M(jw)); take the peak of "
                                         "min_D sigma_max(D M D^-1) of (a)"),
            (max(max(abs(np.linalg.eigvals(M))) for M in Ms), "this is the peak of the spectral radius, a lower "
                                                               "bound, not of the D-scaling upper bound"),
            (mu_upper_ref(Ms[-1]), "this is the bound at the last frequency, not the peak over all frequencies"),
            (mu_upper_ref(Ms[0]), "this is the bound at the first frequency, not the peak over all frequencies"),
            (min(mu_upper_ref(M) for M in Ms), "this is the minimum over frequency; the peak is the maximum"),
        ]
        msg = next((t for val, t in mistakes if _close(x, val) and not _close(val, ref)), None)
        if msg is None and np.isfinite(x) and x < ref:
            at = int(np.argmax([mu_upper_ref(M) for M in Ms]))
            msg = (f"expected {fmt(ref)}, got {fmt(x)}: the bound reaches {fmt(ref)} at w = {fmt(SWEEP_W[at])} "
                   f"rad/s (entry {at}); take the largest bound over all {len(Ms)} frequencies")
        fb.append(f"{tag} {msg or f'expected {fmt(ref)}, got {fmt(x)}'}")
    return score, _correct(fb, n_ok, len(calls), "the peak of the upper bound of both frequency responses")


# ----------------------------------------------------------------------------
# questions
# ----------------------------------------------------------------------------

def questions(rng=None):
    """The five questions with their test inputs."""
    a_calls = [Call(lab, _split(M)) for lab, M in MATRICES.items()]
    b_calls = [Call(lab, _split(MATRICES[lab])) for lab in B_LABELS]
    c_calls = [Call(f"m = {m:g} kg, k = {k:g} N/m, rel = {rel:g}", [m, k, rel]) for m, k, rel in SPRINGS]
    d_calls = [Call("2x2 response, 40 frequencies", _split(sweep(0))),
               Call("3x3 response, 40 frequencies", _split(sweep(1)))]
    return [
        Question("a1", "mu_full", "mu for one full complex block", POINTS["a1"], "float", a_calls,
                 lambda oc: _check_a(oc, a_calls, "full")),
        Question("a2", "mu_scalar_blocks_upper", "D-scaling upper bound for scalar blocks", POINTS["a2"], "float",
                 a_calls, lambda oc: _check_a(oc, a_calls, "scalar")),
        Question("b", "destabilizing_delta", "smallest destabilising diagonal Delta", POINTS["b"], "array",
                 b_calls, lambda oc: _check_b(oc, b_calls)),
        Question("c", "uncertain_spring_lft", "uncertain spring as an upper LFT", POINTS["c"], "ss", c_calls,
                 lambda oc: _check_c(oc, c_calls)),
        Question("d", "mu_peak", "peak of the upper bound over frequency", POINTS["d"], "float", d_calls,
                 lambda oc: _check_d(oc, d_calls)),
    ]


EXERCISE = Exercise("ex02_mu", "The structured singular value: bounds, destabilising Delta, uncertain LFT",
                    questions, stub="exercises/ex02_mu.py", prepare=prepare,
                    blocked_modules=("mutext.mu", "mutext.uncertain", "mutext.dk"))
