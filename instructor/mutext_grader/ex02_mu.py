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

Inputs are drawn per run from the generator the grader passes
(:func:`_draw`), each of the kind of the fixed cases before: the real
rank-one ``2 x 2`` matrix of Skogestad & Postlethwaite's example 8.5 with
its two vectors scaled by 0.7-1.3 (a full-rank variant of it for (a1)), the
complex ``2 x 2`` and ``3 x 3`` matrices and the badly scaled real ``3 x 3``
one with every entry scaled by 0.7-1.3 and turned by up to 0.4 rad (the
real ones only scaled), the mass, stiffness and ``rel`` of (c) 30 % around
the earlier values, the poles, gains and zeros of the two frequency
responses of (d) 30 % around theirs.  A draw is kept only when every
mistake named below gives a value at least 0.5 % (five tolerances) from
the reference, and (b)'s mu is at least 10 % above what the trivial
perturbations reach; so the usual mistakes never pass by chance.  Labels give a case's number and kind;
feedback names the student's value and the mistake, never a reference value
or a drawn number.

What earns nothing (answers that do not solve the question):

* (a1), (a2), (d): a value that is a named shortcut (the spectral radius,
  the Frobenius norm, sigma_max without D-scaling, the real part only, the
  bound at one frequency, ...) where it is wrong; and once a shortcut is
  seen on one matrix, the matrices where it happens to be right (e.g. the
  real part only, on a real matrix) earn nothing either;
* (b): a perturbation that is not diagonal, does not make ``I - M Delta``
  singular, or is no smaller than the ones found without a search: one
  entry ``1/M_ii`` (``Delta = diag(1/M_11, 0, ...)``) or ``I / lambda``
  with an eigenvalue of ``M``; half points need ``1/sigma_max(Delta)`` 2 %
  above both, full points also 98 % of mutext's lower bound;
* (c): a model with the wrong nominal part, or one too large (more than
  :data:`MAX_STATES` states, never computed).

Every size (the shape of (b)'s array, the states and channels of (c)'s
model) is checked in the check function before anything is computed.
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
TRIVIAL_MARGIN = 1.02   # (b): ... and exceed the trivial perturbations' 1/sigma_max by this factor
SINGULAR_TOL = 1e-6     # (b): |det(I - M Delta)| / prod(1 + sigma_i(M Delta))
RTOL_LFT = 1e-6         # (c): closed-loop frequency responses
DELTAS = (-1.0, -0.4, 0.0, 0.6, 1.0)
DISTINCT = 5e-3         # a draw is kept when every named mistake is 5 tolerances (relative) from the reference
TRIVIAL_GAP = 1.10      # (b): mu is at least this factor above the trivial Delta's 1/sigma_max
MAX_STATES = 6          # (c): three times the two states of the mass-spring model

#: the fixed cases the draws perturb: label -> M
BASE = {
    "real 2x2": np.array([[2.0, 2.0], [-1.0, 1.0]]),     # (a1): example 8.5 with a full rank
    "complex 2x2": np.array([[1.0 + 1.0j, 4.0 - 2.0j], [0.2 + 0.1j, 1.5 - 1.0j]]),
    "complex 3x3": np.array([[0.3 - 1.2j, 2.0 + 0.5j, -0.4 + 0.0j],
                             [0.1 + 0.2j, -0.7 + 0.9j, 3.0 - 1.0j],
                             [1.5 + 0.0j, 0.05 - 0.3j, 0.6 + 0.4j]]),
    "badly scaled real 3x3": np.array([[1.0, 20.0, 0.0], [0.05, 1.0, 10.0], [0.5, 0.1, -2.0]]),
}
SP_LABEL = "real rank-one 2x2 (as Skogestad & Postlethwaite, example 8.5)"

#: (c): (m [kg], k [N/m], rel) the draws perturb
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


_LOCK = threading.RLock()


def _key(M):
    M = np.asarray(M, dtype=complex)
    return (M.shape, tuple(M.ravel().tolist()))


@functools.lru_cache(maxsize=2048)
def _upper_cached(key):
    from mutext.mu import mu_upper
    M = np.array(key[1]).reshape(key[0])
    return float(mu_upper(M, _structure(M.shape[0]), method="osborne").value)


def mu_upper_ref(M):
    """D-scaling upper bound (``n`` complex ``1 x 1`` blocks) from :func:`mutext.mu.mu_upper`."""
    with _LOCK:
        return _upper_cached(_key(M))


@functools.lru_cache(maxsize=256)
def _lower_cached(key):
    from mutext.mu import mu_bounds
    M = np.array(key[1]).reshape(key[0])
    return float(mu_bounds(M, _structure(M.shape[0]), method="osborne").lower.value)


def mu_lower_ref(M):
    """Lower bound (``n`` complex ``1 x 1`` blocks) from :func:`mutext.mu.mu_bounds`."""
    with _LOCK:
        return _lower_cached(_key(M))


SWEEP_W = np.logspace(-1, 1.5, 40)     # rad/s


def _sweep2(p):
    """The 2x2 response of (d): ``[[g1/(s+a1), g2 s/den], [-g3/(s+a2), (s+a3)/den]]``, ``den = s^2 + c s + w0^2``."""
    s = 1j * SWEEP_W
    den = s**2 + p["c"] * s + p["w0"] ** 2
    return np.stack([np.array([[p["g1"] / (si + p["a1"]), p["g2"] * si / di],
                               [-p["g3"] / (si + p["a2"]), (si + p["a3"]) / di]]) for si, di in zip(s, den)])


def _sweep3(p):
    """The 3x3 response of (d): a lightly damped pair and a real pole, ``C (sI - A)^-1 B``."""
    s = 1j * SWEEP_W
    A = np.array([[-p["sigma"], p["omega"], 0.0], [-p["omega"], -p["sigma"], 0.0], [0.0, 0.0, -p["pole"]]])
    return np.stack([p["C"] @ np.linalg.solve(si * np.eye(3) - A, p["B"]) for si in s])


def sweep(which, rng=None):
    """Frequency response ``(N, n, n)`` of test system ``which`` of (d): the fixed one without ``rng``,
    else drawn 30 % around it."""
    f = (lambda x: x) if rng is None else (lambda x: x * rng.uniform(0.7, 1.3, np.shape(x)))
    if which == 0:
        return _sweep2({k: float(f(v)) for k, v in
                        dict(g1=2.0, a1=1.0, g2=3.0, g3=0.5, a2=0.5, a3=1.0, c=0.3, w0=2.0).items()})
    B = np.array([[1.0, 0.0, 0.5], [0.0, 2.0, 0.0], [0.3, 0.0, 1.0]])
    C = np.array([[0.0, 1.0, 0.2], [1.0, 0.0, 0.0], [0.1, 0.5, 2.0]])
    return _sweep3(dict(sigma=float(f(0.2)), omega=float(f(3.0)), pole=float(f(1.5)), B=f(B), C=f(C)))


def peak_ref(Ms):
    """The peak over frequency of the upper bound of a response ``(N, n, n)``."""
    return max(mu_upper_ref(M) for M in Ms)


# ----------------------------------------------------------------------------
# inputs drawn per run
# ----------------------------------------------------------------------------

def _perturb(rng, M):
    """Every entry scaled by 0.7-1.3 and, for a complex ``M``, turned by up to 0.4 rad."""
    f = rng.uniform(0.7, 1.3, M.shape)
    if np.iscomplexobj(M):
        return M * f * np.exp(1j * rng.uniform(-0.4, 0.4, M.shape))
    return M * f


def _sp_rank_one(rng):
    u = np.array([2.0, -1.0]) * rng.uniform(0.7, 1.3, 2)
    v = np.array([1.0, 1.0]) * rng.uniform(0.7, 1.3, 2)
    return np.outer(u, v)


def _apart(ref, values):
    return all(not np.isfinite(v) or abs(v - ref) > DISTINCT * abs(ref) for v in values)


def _trivial_delta(M):
    """``1/sigma_max`` of the best perturbation found without a search: one entry ``1/M_ii``, or ``I/lambda``."""
    return max(float(np.abs(np.diag(M)).max()), float(np.abs(np.linalg.eigvals(M)).max()))


def _ok_full(M):
    ref = float(_sv(M)[0])
    vals = [v for v, name, _ in _mistakes_full(M) if not (name == "the real part only" and not M.imag.any())]
    return _apart(ref, vals)


def _ok_scalar(M, with_lower):
    ref = mu_upper_ref(M)
    vals = [v for v, name, _ in _mistakes_scalar(M) if not (name == "the real part only" and not M.imag.any())]
    if not _apart(ref, vals):
        return False
    # mu is the bound here (at most three complex scalar blocks); the lower bound is computed in ``prepare``
    return not with_lower or ref >= TRIVIAL_GAP * _trivial_delta(M)


def _ok_sweep(Ms):
    """Every named mistake of (d) is apart from the peak, decided from singular values and spectral radii
    and the bound at the few frequencies that matter (the whole peak is computed later, in ``prepare``):
    ``rho(M) <= bound <= sigma_max(M)`` at every frequency."""
    sig = np.array([_sv(M)[0] for M in Ms])
    rho = np.array([max(abs(np.linalg.eigvals(M))) for M in Ms])
    low = (1.0 - DISTINCT) * rho.max()          # the peak is at least rho.max()
    # the bound at one frequency, the minimum and the mean are at most the corresponding sigma's
    if max(sig[0], sig[-1], sig.min(), sig.mean()) >= low:
        return False
    # the peak against the peak of rho: the bound where rho peaks is a lower bound of the peak
    if mu_upper_ref(Ms[int(np.argmax(rho))]) <= (1.0 + DISTINCT) * rho.max():
        return False
    # the peak against the peak of sigma: only frequencies with sigma near its peak can bring it near
    near = np.flatnonzero(sig >= (1.0 - DISTINCT) * sig.max())
    return all(mu_upper_ref(Ms[k]) < (1.0 - DISTINCT) * sig.max() for k in near)


def _until(rng, make, ok, tries=200):
    """The first of ``make()``'s draws that passes ``ok`` (the last one tried if none does)."""
    for _ in range(tries):
        x = make()
        if ok(x):
            return x
    return x


def _draw(rng):
    """Every graded input of one run, drawn from ``rng`` (``questions`` and ``prepare`` both call this)."""
    sp = _until(rng, lambda: _sp_rank_one(rng).astype(complex), lambda M: _ok_scalar(M, True))
    sp_full = _until(rng, lambda: _perturb(rng, BASE["real 2x2"]).astype(complex), _ok_full)
    c2 = _until(rng, lambda: _perturb(rng, BASE["complex 2x2"]),
                lambda M: _ok_full(M) and _ok_scalar(M, True))
    c3 = _until(rng, lambda: _perturb(rng, BASE["complex 3x3"]),
                lambda M: _ok_full(M) and _ok_scalar(M, True))
    bs = _until(rng, lambda: _perturb(rng, BASE["badly scaled real 3x3"]).astype(complex),
                lambda M: _ok_full(M) and _ok_scalar(M, False))
    a1 = [("real 2x2", sp_full), ("complex 2x2", c2), ("complex 3x3", c3), ("badly scaled real 3x3", bs)]
    a2 = [(SP_LABEL, sp), ("complex 2x2", c2), ("complex 3x3", c3), ("badly scaled real 3x3", bs)]
    springs = [tuple(float(x * rng.uniform(0.7, 1.3)) for x in base) for base in SPRINGS]
    d = [("2x2 response", _until(rng, lambda: sweep(0, rng), _ok_sweep)),
         ("3x3 response", _until(rng, lambda: sweep(1, rng), _ok_sweep))]
    return {"a1": a1, "a2": a2, "b": a2[:3], "c": springs, "d": d}


def prepare(rng=None):
    """Reference bounds of all calls (the same draws as :func:`questions` with an equal generator)."""
    if rng is not None:
        draw = _draw(rng)
        for _, M in draw["a2"]:
            mu_upper_ref(M)
        for _, M in draw["b"]:
            mu_lower_ref(M)
        for _, Ms in draw["d"]:
            peak_ref(Ms)


# ----------------------------------------------------------------------------
# helpers
# ----------------------------------------------------------------------------


def _close(x, ref, rtol=RTOL_MU):
    return bool(np.isfinite(x) and abs(x - ref) <= rtol * max(abs(ref), 1e-12))


def _sv(M):
    return np.linalg.svd(M, compute_uv=False)


@functools.lru_cache(maxsize=256)
def _dmd_cached(key):
    M = np.array(key[1]).reshape(key[0])
    n = M.shape[0]

    def f(x):
        d = np.exp(np.clip(np.concatenate([x, [0.0]]), -30, 30))
        return np.log(_sv(d[:, None] * M * d[None, :])[0])

    r = minimize(f, np.zeros(n - 1), method="Nelder-Mead",
                 options={"xatol": 1e-10, "fatol": 1e-13, "maxiter": 20000, "maxfev": 20000})
    return float(np.exp(r.fun))


def dmd_value(M):
    """``min sigma_max(D M D)`` with the last entry of ``D`` fixed to 1 (the mistake ``D M D``)."""
    with _LOCK:
        return _dmd_cached(_key(M))


def _mistakes_scalar(M):
    """``(value, name, text)`` of the usual wrong answers for ``n`` complex scalar blocks."""
    sv = _sv(M)
    return [
        (sv[0], "sigma_max(M)", "no D-scaling: this is sigma_max(M), mu for one full block; minimise "
                                "sigma_max(D M D^-1) over positive diagonal D"),
        (max(abs(np.linalg.eigvals(M))), "the spectral radius",
         "returned the spectral radius max|eig(M)|, a lower bound on mu (not the D-scaling upper bound)"),
        (dmd_value(M), "D M D", "D applied as D M D instead of D M D^-1 (the scaling must be a similarity)"),
        (mu_upper_ref(M.real) if M.shape[0] > 0 else np.nan, "the real part only",
         "this is the bound of the real part of M only: build M = M_re + 1j*M_im"),
    ]


def _mistakes_full(M):
    sv = _sv(M)
    return [
        (max(abs(np.linalg.eigvals(M))), "the spectral radius",
         "returned the spectral radius max|eig(M)|, not the largest singular value (the spectral radius is "
         "mu of a repeated scalar block delta I)"),
        (np.linalg.norm(M, "fro"), "the Frobenius norm", "returned the Frobenius norm, not the largest singular value"),
        (sv[-1], "the smallest singular value", "returned the smallest singular value, not the largest"),
        (sv[0] ** 2, "sigma_max^2", "returned sigma_max^2 (the largest eigenvalue of M^H M): take the square root"),
        (_sv(M.real)[0], "the real part only",
         "this is sigma_max of the real part of M only: build M = M_re + 1j*M_im"),
    ]


def _band(x, ref):
    """How far ``x`` is from ``ref``, in words that do not give ``ref`` away."""
    r = abs(x / ref - 1.0) if ref else np.inf
    side = "too high" if x > ref else "too low"
    if r < 1e-2:
        return f"{side} by less than 1 %"
    if r < 0.1:
        return f"{side} by 1-10 %"
    return f"{side} by more than 10 %"


def _diagnose(x, ref, mistakes, sigma=None):
    texts = [text for val, _, text in mistakes if _close(x, val) and not _close(val, ref)]
    if texts:
        return "; or ".join(texts)      # e.g. rho(M) and min sigma(D M D) coincide for a rank-one M
    if not np.isfinite(x):
        return "the value is not finite"
    if sigma is not None and ref < x < sigma:
        return (f"your value {fmt(x)} lies between the optimum and sigma_max(M), so the minimisation over D did "
                "not converge (tighten the tolerance, or bisect on the LMI M^H X M - beta^2 X <= 0)")
    return f"your value {fmt(x)} is {_band(x, ref)}"


def _caught(x, ref, mistakes):
    """Names of the mistakes ``x`` is (where they are wrong)."""
    return {name for val, name, _ in mistakes if _close(x, val) and not _close(val, ref)}


def _easy(ref, mistakes):
    """Names of the mistakes that happen to give ``ref``."""
    return {name for val, name, _ in mistakes if _close(val, ref)}


def _score_right(fb, right, easy, caught, labels, per):
    """Points of the right calls; none where a shortcut seen elsewhere happens to be right."""
    score, n_ok = 0.0, 0
    for ok, e, label in zip(right, easy, labels):
        if ok and e & caught:
            fb.append(f"[{label}] 0 points: the shortcut seen on another case ({sorted(e & caught)[0]}) happens to "
                      "give this case's value")
        elif ok:
            score += per
            n_ok += 1
    return score, n_ok


def _correct(fb, n_ok, n, text):
    if n_ok == n:
        fb.insert(0, f"correct: {text}")
    return fb


# ----------------------------------------------------------------------------
# (a) mu of one full block and the D-scaling upper bound
# ----------------------------------------------------------------------------

def _check_a(outcomes, calls, which, matrices):
    qid = "a1" if which == "full" else "a2"
    per = POINTS[qid] / len(calls)
    fb, right, easy, caught = [], [], [], set()
    for call, oc, (_, M) in zip(calls, outcomes, matrices):
        if which == "full":
            ref, mistakes = float(_sv(M)[0]), _mistakes_full(M)
        else:
            ref, mistakes = mu_upper_ref(M), _mistakes_scalar(M)
        easy.append(_easy(ref, mistakes))
        if not oc["ok"]:
            fb.append(f"[{call.label}] {oc['error']}")
            right.append(False)
            continue
        x = float(oc["value"])
        right.append(_close(x, ref))
        if right[-1]:
            continue
        caught |= _caught(x, ref, mistakes)
        sigma = None if which == "full" else float(_sv(M)[0])
        fb.append(f"[{call.label}] {_diagnose(x, ref, mistakes, sigma)}")
    score, n_ok = _score_right(fb, right, easy, caught, [c.label for c in calls], per)
    what = "sigma_max(M) of every matrix" if which == "full" else "the D-scaling bound of every matrix"
    return score, _correct(fb, n_ok, len(calls), what)


# ----------------------------------------------------------------------------
# (b) destabilising perturbation
# ----------------------------------------------------------------------------

def _residual(M, Delta):
    """``|det(I - M Delta)|`` relative to ``prod(1 + sigma_i(M Delta))``."""
    MD = M @ Delta
    return float(abs(np.linalg.det(np.eye(M.shape[0]) - MD)) / np.prod(1.0 + _sv(MD)))


def _check_b(outcomes, calls, matrices):
    per = POINTS["b"] / len(calls)
    score, fb, n_ok = 0.0, [], 0
    for call, oc, (_, M) in zip(calls, outcomes, matrices):
        tag = f"[{call.label}]"
        if not oc["ok"]:
            fb.append(f"{tag} {oc['error']}")
            continue
        n = M.shape[0]
        shape = oc["value"].get("shape") if isinstance(oc["value"], dict) else None
        if shape not in ([2, n, n], [2, n]):        # checked before the data are read
            fb.append(f"{tag} return the pair (Delta.real, Delta.imag) of the {n}x{n} diagonal Delta "
                      f"(an array of shape (2, {n}, {n})), got shape {tuple(shape) if isinstance(shape, list) else shape}")
            continue
        X, err = as_array(oc["value"], "destabilizing_delta()")
        if err:
            fb.append(f"{tag} {err}")
            continue
        if X.shape == (2, n):
            X = np.stack([np.diag(X[0]), np.diag(X[1])])
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
        if mu_d <= TRIVIAL_MARGIN * _trivial_delta(M):
            fb.append(f"{tag} 0 points: Delta destabilises (1/sigma_max(Delta) = {fmt(mu_d)}), but it is no smaller "
                      "than a perturbation found without any search (one entry 1/M_ii, as diag(1/M_11, 0, ...), "
                      "or I / lambda with an eigenvalue lambda of M): maximise rho(M U) over diagonal unitary U")
            continue
        if mu_d >= LOWER_FRACTION * mu_lower_ref(M):
            score += per
            n_ok += 1
            continue
        score += per / 2
        fb.append(f"{tag} half points: Delta destabilises and 1/sigma_max(Delta) = {fmt(mu_d)} beats the trivial "
                  f"perturbations, but a diagonal Delta more than {100 * (1 - LOWER_FRACTION):g} % smaller exists: "
                  "maximise rho(M U) over diagonal unitary U")
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
        return "the size rel is missing: your k varies as k (1 + delta), expected k (1 + rel delta)"
    return f"closing w = delta z gives k (1 + {c:.4g} delta), expected k (1 + rel delta)"


def _raw_dims(value):
    """Upper bounds of (states, inputs, outputs) read off the returned lists, before any matrix is built."""
    A, B, C, D = (value.get(k) or [] for k in "ABCD")
    n = max(len(A), max((len(r) for r in A), default=0), len(B), max((len(r) for r in C), default=0))
    m = max(max((len(r) for r in B), default=0), max((len(r) for r in D), default=0))
    return n, m, max(len(C), len(D))


def _check_c(outcomes, calls):
    per = POINTS["c"] / len(calls)
    score, fb, n_ok = 0.0, [], 0
    for call, tag, value in returned(outcomes, calls, fb):
        v = value
        n, n_in, n_out = _raw_dims(v)
        if n > MAX_STATES:
            fb.append(f"{tag} the model has {n} states; at most {MAX_STATES} are accepted (three times the 2 of "
                      "the mass-spring model): not evaluated, 0 points")
            continue
        if n_in > 2 or n_out > 2:
            fb.append(f"{tag} P must have 2 inputs [w, f] and 2 outputs [z, x], got {n_in} inputs and "
                      f"{n_out} outputs")
            continue
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

def _mistakes_peak(Ms):
    """``(value, name, text)`` of the usual wrong answers for the peak over frequency."""
    bounds = [mu_upper_ref(M) for M in Ms]
    return [
        (max(_sv(M)[0] for M in Ms), "sigma_max(M(jw))", "no D-scaling: this is the peak of sigma_max(M(jw)); take "
                                                         "the peak of min_D sigma_max(D M D^-1) of (a)"),
        (max(max(abs(np.linalg.eigvals(M))) for M in Ms), "the spectral radius",
         "this is the peak of the spectral radius, a lower bound, not of the D-scaling upper bound"),
        (bounds[-1], "the last frequency", "this is the bound at the last frequency, not the peak over all "
                                           "frequencies"),
        (bounds[0], "the first frequency", "this is the bound at the first frequency, not the peak over all "
                                           "frequencies"),
        (min(bounds), "the minimum", "this is the minimum over frequency; the peak is the maximum"),
        (float(np.mean(bounds)), "the mean", "this is the mean over frequency; the peak is the maximum"),
    ]


def _check_d(outcomes, calls, sweeps):
    per = POINTS["d"] / len(calls)
    fb, right, easy, caught = [], [], [], set()
    for call, oc, (_, Ms) in zip(calls, outcomes, sweeps):
        tag = f"[{call.label}]"
        ref = peak_ref(Ms)
        mistakes = _mistakes_peak(Ms)
        easy.append(_easy(ref, mistakes))
        if not oc["ok"]:
            fb.append(f"{tag} {oc['error']}")
            right.append(False)
            continue
        x = float(oc["value"])
        right.append(_close(x, ref))
        if right[-1]:
            continue
        caught |= _caught(x, ref, mistakes)
        msg = next((t for val, _, t in mistakes if _close(x, val) and not _close(val, ref)), None)
        if msg is None and np.isfinite(x) and x < ref:
            msg = (f"your value {fmt(x)} is {_band(x, ref)}: the bound is larger at some frequency; take the "
                   f"largest bound over all {len(Ms)} frequencies")
        fb.append(f"{tag} {msg or _diagnose(x, ref, [])}")
    score, n_ok = _score_right(fb, right, easy, caught, [c.label for c in calls], per)
    return score, _correct(fb, n_ok, len(calls), "the peak of the upper bound of both frequency responses")


# ----------------------------------------------------------------------------
# questions
# ----------------------------------------------------------------------------

def questions(rng=None):
    """The five questions with their inputs drawn from ``rng`` (a fresh generator without one)."""
    draw = _draw(rng if rng is not None else np.random.default_rng())

    def calls(cases):
        return [Call(f"matrix {i + 1} of {len(cases)}: {lab}", _split(M)) for i, (lab, M) in enumerate(cases)]
    a1_calls, a2_calls, b_calls = calls(draw["a1"]), calls(draw["a2"]), calls(draw["b"])
    c_calls = [Call(f"parameter set {i + 1} of {len(draw['c'])}", list(p)) for i, p in enumerate(draw["c"])]
    d_calls = [Call(f"{lab}, {len(Ms)} frequencies", _split(Ms)) for lab, Ms in draw["d"]]
    return [
        Question("a1", "mu_full", "mu for one full complex block", POINTS["a1"], "float", a1_calls,
                 lambda oc: _check_a(oc, a1_calls, "full", draw["a1"])),
        Question("a2", "mu_scalar_blocks_upper", "D-scaling upper bound for scalar blocks", POINTS["a2"], "float",
                 a2_calls, lambda oc: _check_a(oc, a2_calls, "scalar", draw["a2"])),
        Question("b", "destabilizing_delta", "smallest destabilising diagonal Delta", POINTS["b"], "array",
                 b_calls, lambda oc: _check_b(oc, b_calls, draw["b"])),
        Question("c", "uncertain_spring_lft", "uncertain spring as an upper LFT", POINTS["c"], "ss", c_calls,
                 lambda oc: _check_c(oc, c_calls)),
        Question("d", "mu_peak", "peak of the upper bound over frequency", POINTS["d"], "float", d_calls,
                 lambda oc: _check_d(oc, d_calls, draw["d"])),
    ]


EXERCISE = Exercise("ex02_mu", "The structured singular value: bounds, destabilising Delta, uncertain LFT",
                    questions, stub="exercises/ex02_mu.py", prepare=prepare,
                    blocked_modules=("mutext.mu", "mutext.uncertain", "mutext.dk"))
