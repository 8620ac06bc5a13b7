r"""Grader of exercise ``ex04_beam_element``: Euler-Bernoulli beam elements in numpy.

Questions (10 points):

(a) ``element_matrices(E, I, rho, A, L)``, 3 points: the 4x4 stiffness and
    consistent mass matrices, DOFs ``[w1, theta1, w2, theta2]``, at two
    parameter sets (0.75 points per matrix and set).
(b) ``assemble(n_elements, length, E, I, rho, A, support)``, 2 points: the
    global ``(K, M)`` of a pinned-pinned and of a cantilever beam with the
    supports applied (0.5 points per matrix and beam; half of that when the
    matrices are right but the supports are not applied or the DOFs are in
    another order).
(c) ``natural_frequencies(...)``, 2 points: the lowest frequencies in rad/s
    of two beams (1 point each).
(d) ``relative_errors(...)``, 3 points: ``(omega_N - omega_exact)/omega_exact``
    for three element counts N drawn per call (2-3, 3-5, 5-8), three beams and
    modes (1 point each).

Inputs are drawn per run from the generator the grader passes
(:func:`draw`): materials (steel, aluminium, titanium, brass, E and rho
within 5 %), solid sections of 10-40 mm, a short (0.15-0.6 m) and a long
(1.6-3 m) element in (a), beams of 0.5-2 m with 3-5 elements in (b) and 3-6
in (c) (3 or 4 modes), the modes of (d) (pinned-pinned mode 1 or 2,
cantilever mode 1, cantilever mode 2 or 3) with their element counts, and
the order of the calls.
:func:`prepare` builds the references of the same draw while the child runs.

The references are computed with :mod:`mutext.rotor` (Timoshenko shaft
elements with shear deformation and rotary inertia switched off, which is
the Euler-Bernoulli element) and the exact Euler-Bernoulli frequencies
:math:`\omega_n = (\beta_n L)^2\sqrt{EI/(\rho A L^4)}`.  Submissions may not
import :mod:`mutext.rotor` (it computes the answers).

What earns points: matrices and frequencies within 1e-6 (relative to the
largest entry) of the reference, the errors of (d) within 1e-4 relative
plus 1e-9; half of a beam's points in (b) for the right free-beam matrices
(supports not applied) or the right beam in another DOF order.  Zeros,
identity matrices, constants and the closed-form frequencies in (c) (the
finite-element ones are asked) earn nothing
(``tests/grading_submissions/trivial/ex04_*.py``).  Sizes are checked before
anything is computed: an array of another shape than asked, e.g. matrices
far larger than ``2N x 2N``, scores 0 for that call with a message and is
never factorised.  The errors of (d) are dimensionless (they depend only on
the support, the mode and N, not on the beam): the element counts are drawn
per call, so a table of them copied from one run does not pass another.

Feedback names the call by number with its support, number of elements and
modes (arguments, not answers) and the usual mistakes, never a reference
value (a factor is quoted only when it is a simple ratio such as 1/2, or a
power of L): a lumped instead of a consistent mass matrix, a factor
:math:`L` missing in the rotational terms, a wrong prefactor, another DOF
order or rotation sign, supports not applied (rigid-body zero frequencies),
Hz instead of rad/s, an inaccurate analytic value.
"""
from __future__ import annotations

import functools
import math
import threading

import numpy as np
import scipy.linalg as sla

from .compare import as_array, fmt, returned
from .core import Call, Exercise, Question

POINTS = {"a": 3.0, "b": 2.0, "c": 2.0, "d": 3.0}
RTOL = 1e-6            # matrices and frequencies: max |error| / max |reference|
RTOL_ERR = 1e-4        # relative errors of (d): relative to the error itself ...
ATOL_ERR = 1e-9        # ... plus this absolute slack (the errors reach 1e-6)

SUPPORT_TEXT = {"pinned": "pinned-pinned", "cantilever": "cantilever"}

#: (name, E Pa, rho kg/m^3) of the materials a test beam is drawn from; E and rho then vary by +-5 %
MATERIALS = (("steel", 2.1e11, 7800.0), ("aluminium", 7.0e10, 2700.0), ("titanium", 1.1e11, 4500.0),
             ("brass", 1.0e11, 8500.0))
DIAMETER = (0.010, 0.040)                    # m, solid circular sections
#: element lengths (m) of the two parameter sets of (a): one short, one long, both far from 1 m, so that a
#: wrong power of L in a prefactor or in the rotational terms shows
ELEMENT_LENGTHS = ((0.15, 0.6), (1.6, 3.0))
BEAM_LENGTH = (0.5, 2.0)                     # m, the beams of (b), (c), (d)
ELEMENTS_B = (3, 5)                          # elements of the beams of (b) (inclusive range)
ELEMENTS_C = (3, 6)                          # ... and of (c)
MODES_C = (3, 4)                             # frequencies asked in (c)
#: (support, modes one is drawn from) of the three calls of (d), shuffled
D_CASES = (("pinned", (1, 2)), ("cantilever", (1,)), ("cantilever", (2, 3)))
#: element counts of (d): three increasing counts drawn from these ranges (the largest at most 8, where the
#: error of a cubic element is still far above rounding), so the errors asked differ from run to run and no
#: table of them can be copied
D_COUNTS = ((2, 3), (3, 5), (5, 8))
DOF_NAMES = ["w1", "theta1", "w2", "theta2"]
ROT = np.array([0, 1, 0, 1])          # 1 where the element DOF is a rotation


def section(d):
    """Area and second moment of area of a solid circle of diameter ``d`` (m^2, m^4)."""
    return math.pi * d**2 / 4.0, math.pi * d**4 / 64.0


def beam_args(mat):
    """``(E, I, rho, A)`` of a material dict, as the student's functions take them."""
    A, I = section(mat["d"])
    return mat["E"], I, mat["rho"], A


def _material(rng):
    _, E, rho = MATERIALS[int(rng.integers(len(MATERIALS)))]
    return dict(E=float(f"{E * rng.uniform(0.95, 1.05):.3g}"), rho=float(round(rho * rng.uniform(0.95, 1.05))),
                d=round(float(rng.uniform(*DIAMETER)), 4))


def _length(rng, lo_hi):
    return round(float(math.exp(rng.uniform(*np.log(lo_hi)))), 3)


def _counts(rng):
    """Three increasing element counts for (d), from :data:`D_COUNTS`."""
    out = []
    for lo, hi in D_COUNTS:
        lo = max(lo, out[-1] + 1) if out else lo
        out.append(int(rng.integers(lo, hi + 1)))
    return tuple(out)


def draw(rng):
    """The graded inputs of one run, from the numpy Generator ``rng``.

    Returns a dict: ``"a"``, two ``(material, L)`` (one short and one long element, shuffled); ``"b"``,
    ``(n, length, material, support)`` of a pinned-pinned and a cantilever beam (shuffled); ``"c"``,
    ``(n, length, material, support, n_modes)`` likewise; ``"d"``, three ``(length, material, support,
    mode, element_counts)`` (:data:`D_CASES`, :data:`D_COUNTS`, shuffled).  A material is a dict ``E``, ``rho``, ``d`` (the section's
    diameter, which the reference needs; the child gets ``I`` and ``A``).
    """
    a = [(_material(rng), _length(rng, lo_hi)) for lo_hi in ELEMENT_LENGTHS]
    a = [a[i] for i in rng.permutation(2)]
    b = [(int(rng.integers(ELEMENTS_B[0], ELEMENTS_B[1] + 1)), _length(rng, BEAM_LENGTH), _material(rng), sup)
         for sup in ("pinned", "cantilever")]
    b = [b[i] for i in rng.permutation(2)]
    c = [(int(rng.integers(ELEMENTS_C[0], ELEMENTS_C[1] + 1)), _length(rng, BEAM_LENGTH), _material(rng), sup,
          int(rng.integers(MODES_C[0], MODES_C[1] + 1))) for sup in ("pinned", "cantilever")]
    c = [c[i] for i in rng.permutation(2)]
    d = [(_length(rng, BEAM_LENGTH), _material(rng), sup, int(rng.choice(modes)), _counts(rng))
         for sup, modes in D_CASES]
    d = [d[i] for i in rng.permutation(3)]
    return {"a": a, "b": b, "c": c, "d": d}


# ----------------------------------------------------------------------------
# references (mutext.rotor and analytic)
# ----------------------------------------------------------------------------

def element_reference(E, d, rho, L):
    """``(K, Mt, Mr)`` of one element from :mod:`mutext.rotor` without shear (Euler-Bernoulli)."""
    from mutext.rotor.elements import timoshenko_plane_matrices
    Mt, Mr, K = timoshenko_plane_matrices(E, E / 2.6, rho, L, d, 0.0, 1.0, shear=False)
    return tuple(np.asarray(X.full() if hasattr(X, "full") else X, dtype=float) for X in (K, Mt, Mr))


def _free_free(n, length, E, d, rho):
    """Global ``(K, M)`` of ``n`` Euler-Bernoulli elements, no supports, from a :class:`mutext.rotor.Rotor`."""
    from mutext.rotor import Param, Rotor, ShaftElement
    mat = dict(E=Param("E", E), rho=Param("rho", rho), nu=Param("nu", 0.3))
    els = [ShaftElement(i + 1, length / n, d, 0.0, **mat, shear=False, rotary_inertia=False) for i in range(n)]
    M, _, K, _ = Rotor(els, planes=1).matrices()      # plane layout (u, psi), psi = du/dz: (w, theta)
    return K, M


_LOCK = threading.Lock()


@functools.lru_cache(maxsize=64)
def _free_free_cached(n, length, E, d, rho):
    return _free_free(n, length, E, d, rho)


def free_free(n, length, E, d, rho):
    with _LOCK:
        K, M = _free_free_cached(n, length, E, d, rho)
    return K.copy(), M.copy()


def constrained(n, support):
    """0-based global DOFs fixed by the supports (order ``w1, theta1, w2, theta2, ...``)."""
    return [0, 2 * n] if support == "pinned" else [0, 1]


def reduce(K, M, fixed):
    free = np.setdiff1d(np.arange(K.shape[0]), fixed)
    return K[np.ix_(free, free)], M[np.ix_(free, free)]


def supported(n, length, E, d, rho, support):
    return reduce(*free_free(n, length, E, d, rho), constrained(n, support))


def frequencies(K, M, n_modes=None):
    """Natural frequencies (rad/s) of ``(K, M)``, ascending; massless DOFs (lumped mass) are condensed out."""
    if np.all(np.linalg.eigvalsh(M) > 1e-12 * np.abs(M).max()):
        lam = sla.eigh(K, M, eigvals_only=True)
    else:
        lam = sla.eigvals(K, M)
        lam = np.sort(lam[np.isfinite(lam)].real)
    w = np.sqrt(np.maximum(lam, 0.0))
    return w if n_modes is None else w[:n_modes]


def exact_frequency(length, E, d, rho, support, mode):
    """Exact Euler-Bernoulli frequency [rad/s] of mode ``mode`` (1-based)."""
    from mutext.rotor.analytic import euler_bernoulli_frequency
    return euler_bernoulli_frequency(mode, length, E, rho, *section(d), support)


def reference_errors(length, E, d, rho, support, mode, counts=(2, 4, 8)):
    exact = exact_frequency(length, E, d, rho, support, mode)
    return np.array([frequencies(*supported(n, length, E, d, rho, support))[mode - 1] / exact - 1.0
                     for n in counts])


def _lumped_free_free(n, length, E, d, rho):
    K, _ = free_free(n, length, E, d, rho)
    A, _ = section(d)
    m = rho * A * length / n
    M = np.zeros_like(K)
    for e in range(n):
        M[2 * e, 2 * e] += m / 2
        M[2 * e + 2, 2 * e + 2] += m / 2
    return K, M


def prepare(rng=None):
    """Build the references of this run's calls (the CasADi models) while the child runs; ``rng`` is
    seeded as the one :func:`questions` gets, so :func:`draw` gives the same beams."""
    if rng is None:
        return
    cases = draw(rng)
    beams = [(n, length, mat) for n, length, mat, *_ in cases["b"] + cases["c"]]
    beams += [(n, length, mat) for length, mat, _, _, counts in cases["d"] for n in counts]
    for n, length, mat in beams:
        free_free(n, length, mat["E"], mat["d"], mat["rho"])


# ----------------------------------------------------------------------------
# helpers
# ----------------------------------------------------------------------------


def close(X, Y, rtol=RTOL):
    """Same shape and ``max|X - Y| <= rtol max|Y|`` (False on NaN)."""
    if X.shape != Y.shape:
        return False
    with np.errstate(invalid="ignore"):
        return bool(np.all(np.abs(X - Y) <= rtol * max(np.abs(Y).max(), 1e-300)))


def _factor(X, Y):
    """``c`` with ``X = c Y`` (to ``RTOL``), else None."""
    den = float(np.sum(Y * Y))
    if X.shape != Y.shape or den == 0 or not np.all(np.isfinite(X)):
        return None
    c = float(np.sum(X * Y)) / den
    return c if c != 0 and close(X, c * Y) else None


def _power_of(c, L, kmax=3):
    """Integer ``k != 0`` with ``c = L^k`` (to 1e-6), else None."""
    for k in range(-kmax, kmax + 1):
        if k and abs(c / L**k - 1.0) <= 1e-6:
            return k
    return None


def _rotation_pattern(X, Y, L):
    r"""``(c, p)`` if ``X_ij = c L^{p (r_i + r_j)} Y_ij`` (``r`` = 1 on rotations), ``p != 0``; else None."""
    if X.shape != (4, 4) or not np.all(np.isfinite(X)):
        return None
    nz = np.abs(Y) > 1e-12 * np.abs(Y).max()
    r = (ROT[:, None] + ROT[None, :])[nz]
    R = X[nz] / Y[nz]
    groups = [R[r == k] for k in (0, 1, 2)]
    if any(g.size == 0 for g in groups):
        return None
    means = [float(np.mean(g)) for g in groups]
    if any(m == 0 or np.any(np.abs(g - m) > 1e-6 * abs(m)) for g, m in zip(groups, means)):
        return None
    q1, q2 = means[1] / means[0], means[2] / means[0]
    if q1 <= 0 or abs(q2 / q1**2 - 1) > 1e-6:
        return None
    p = math.log(q1) / math.log(L)
    if abs(p - round(p)) > 1e-6 or round(p) == 0:
        return None
    return means[0], int(round(p))


def _worst_entry(X, Y, names):
    """Where ``X`` differs most from ``Y``, and which way (the reference value is not given)."""
    err = np.abs(X - Y)
    i, j = np.unravel_index(int(np.nanargmax(np.where(np.isfinite(err), err, np.inf))), X.shape)
    how = "not finite" if not np.isfinite(X[i, j]) else ("too large" if X[i, j] > Y[i, j] else "too small")
    return f"the largest difference is in entry ({names[i]}, {names[j]}), yours is {how}"


def _simple_factor(c):
    """``c`` as text if it is a simple ratio ``p/q`` (|p|, q <= 12), the trace of a known slip; else None,
    since an arbitrary factor would tell the reference."""
    for q in range(1, 13):
        p = round(c * q)
        if p and abs(p) <= 12 and abs(c * q - p) <= 1e-6 * abs(p):
            return fmt(p / q)
    return None


def _power_text(k):
    return "L" if k == 1 else f"L^{k}"


# ----------------------------------------------------------------------------
# (a) element matrices
# ----------------------------------------------------------------------------

PERM = [0, 2, 1, 3]                     # [w1, w2, theta1, theta2]
SIGN = np.diag([1.0, -1.0, 1.0, -1.0])  # theta = -dw/dz


def _diagnose_element(X, Y, L, which, Mr=None):
    """Why the submitted element matrix ``X`` differs from ``Y`` (``which`` is "K" or "M")."""
    name = "stiffness matrix K" if which == "K" else "mass matrix M"
    pref = "EI/L^3" if which == "K" else "rho A L/420"
    if X.shape != (4, 4):
        return f"the {name} must be 4x4 (DOFs [w1, theta1, w2, theta2]), got shape {X.shape}"
    if not np.all(np.isfinite(X)):
        return f"the {name} has entries that are not finite"
    if which == "M":
        off = X - np.diag(np.diag(X))
        if np.all(np.abs(off) <= 1e-12 * max(np.abs(X).max(), 1e-300)):
            return ("the mass matrix is lumped, not consistent: it is diagonal. The consistent mass matrix "
                    "M = rho A L/420 [156, 22L, 54, -13L; ...] comes from the same cubic shape functions as K "
                    "and couples all four DOFs")
        if Mr is not None and close(X, Y + Mr):
            return ("the mass matrix includes the rotary inertia rho I (a Rayleigh beam); the Euler-Bernoulli "
                    "element here has translational inertia rho A only")
    if close(X, Y[np.ix_(PERM, PERM)]):
        return (f"the {name} has its DOFs in the order [w1, w2, theta1, theta2]; the expected order is "
                "[w1, theta1, w2, theta2] (node by node)")
    if close(X, SIGN @ Y @ SIGN):
        return (f"the {name} has the signs of the deflection-rotation coupling terms flipped: "
                "theta is dw/dz (counterclockwise positive), not -dw/dz")
    c = _factor(X, Y)
    if c is not None:
        k = _power_of(c, L)
        if k is not None:
            extra = (f" (e.g. EI/L^{3 - k} instead of EI/L^3)" if which == "K"
                     else f" (e.g. rho A L^{1 + k}/420 instead of rho A L/420)")
            return (f"the {name} is {_power_text(k)} times the expected one: check the power of L in the "
                    f"prefactor {pref}{extra}")
        nice = _simple_factor(c)
        if nice is not None:
            return f"the {name} is {nice} times the expected one: check the prefactor {pref}"
        return f"the {name} is proportional to the expected one with another factor: check the prefactor {pref}"
    pat = _rotation_pattern(X, Y, L)
    if pat is not None:
        c, p = pat
        terms = "6L, 4L^2, 2L^2" if which == "K" else "22L, 13L, 4L^2, 3L^2"
        if p < 0:
            msg = (f"a factor {_power_text(-p)} is missing in the rotational terms of the {name} "
                   f"(the entries of the theta rows and columns: {terms})")
        else:
            msg = (f"the rotational terms of the {name} have an extra factor {_power_text(p)} "
                   f"(the entries of the theta rows and columns should be {terms})")
        if abs(c - 1) > 1e-6:
            nice = _simple_factor(c)
            msg += (f"; moreover the prefactor is {nice} times {pref}" if nice is not None
                    else f"; moreover the prefactor {pref} is not right")
        return msg
    fb = f"the {name} is not right: {_worst_entry(X, Y, DOF_NAMES)}"
    if not close(X, X.T):
        fb += f"; note that your {name} is not symmetric"
    return fb


def _check_element(outcomes, calls):
    per = POINTS["a"] / (2 * len(calls))
    score, fb, n_ok = 0.0, [], 0
    for call, tag, V in returned(outcomes, calls, fb, as_array, "element_matrices()"):
        if V.shape != (2, 4, 4):
            fb.append(f"{tag} element_matrices() must return the pair (K, M) of 4x4 arrays, got an array of "
                      f"shape {V.shape}")
            continue
        E, I, rho, A, L = call.args
        K, Mt, Mr = element_reference(E, call.kwargs_ref["d"], rho, L)
        Ks, Ms = V
        if close(Ks, Mt) and close(Ms, K):
            fb.append(f"{tag} K and M are swapped: return (K, M)")
            continue
        for X, Y, which in ((Ks, K, "K"), (Ms, Mt, "M")):
            if close(X, Y):
                score += per
                n_ok += 1
            else:
                fb.append(f"{tag} " + _diagnose_element(X, Y, L, which, Mr))
    if n_ok == 2 * len(calls):
        fb.insert(0, "correct: K and M match at both parameter sets")
    return score, fb


# ----------------------------------------------------------------------------
# (b) assembly
# ----------------------------------------------------------------------------

def _same_spectrum(Ks, Ms, K, M):
    try:
        a = frequencies(Ks, Ms)
    except Exception:   # noqa: BLE001 - a singular or indefinite submitted mass matrix
        return False
    return close(a, frequencies(K, M))


def _check_assembly(outcomes, calls):
    per = POINTS["b"] / (2 * len(calls))
    score, fb, n_ok = 0.0, [], 0
    for call, tag, V in returned(outcomes, calls, fb, as_array, "assemble()"):
        n, length, E, I, rho, A, support = call.args
        d = call.kwargs_ref["d"]
        if V.ndim != 3 or V.shape[0] != 2 or V.shape[1] != V.shape[2]:
            fb.append(f"{tag} assemble() must return the pair (K, M) of square arrays, got an array of shape "
                      f"{V.shape}")
            continue
        size = V.shape[1]
        if size > 2 * (2 * n + 2):
            fb.append(f"{tag} the matrices are {size}x{size}, far larger than the {2 * n}x{2 * n} asked for "
                      f"{n} elements (2 DOFs per node, {n + 1} nodes, 2 fixed by the supports): not analysed")
            continue
        Ks, Ms = V
        K, M = supported(n, length, E, d, rho, support)
        fixed = constrained(n, support)
        if close(Ks, K) and close(Ms, M):
            score += 2 * per
            n_ok += 2
            continue
        if size == 2 * (n + 1):
            K0, M0 = free_free(n, length, E, d, rho)
            got = [close(Ks, K0), close(Ms, M0)]
            score += 0.5 * per * sum(got)
            fb.append(f"{tag} boundary conditions not applied: the matrices are {size}x{size}, those of the free "
                      f"beam; remove the rows and columns of the DOFs the supports fix "
                      f"({', '.join(_global_name(k) for k in fixed)} for a {SUPPORT_TEXT[support]} beam), "
                      f"leaving {2 * n}x{2 * n}" + ("" if all(got) else
                                                    "; the free-beam matrices are not right either"))
            continue
        if size in (4 * n, 4 * n - 2):
            fb.append(f"{tag} the matrices are {size}x{size}: the elements look unconnected. Neighbouring "
                      "elements share a node: add each element's 4x4 matrix into the global rows and columns "
                      "[2e, 2e+1, 2e+2, 2e+3] (e = 0, 1, ...), so the shared 2x2 blocks overlap")
            continue
        if size != 2 * n:
            fb.append(f"{tag} expected {2 * n}x{2 * n} matrices ({n} elements, {2 * (n + 1)} DOFs, "
                      f"{len(fixed)} fixed by the supports), got {size}x{size}")
            continue
        other = "cantilever" if support == "pinned" else "pinned"
        alternatives = [
            (supported(n, length, E, d, rho, other), f"these are the matrices of a {SUPPORT_TEXT[other]} beam; "
                                                     f"this call asks for a {SUPPORT_TEXT[support]} beam"),
            (reduce(*free_free(n, length, E, d, rho), [2 * n, 2 * n + 1]),
             "the beam is clamped at z = length; the cantilever is clamped at node 1 (z = 0): fix w1 and theta1"),
            (supported(n, length * n, E, d, rho, support),
             f"every element has the full length {length:g} m: an element is length/n_elements long"),
        ]
        hint = None
        for (Ka, Ma), text in alternatives:
            if close(Ks, Ka) and close(Ms, Ma):
                hint = text
                break
        if hint is None and _same_spectrum(Ks, Ms, K, M):
            score += per          # right beam, other DOF order: half the points
            hint = ("the matrices have the right natural frequencies but the DOFs are in another order; expected "
                    "w1, theta1, w2, theta2, ... (node by node) with the fixed DOFs removed")
        if hint is not None:
            fb.append(f"{tag} {hint}")
            continue
        for X, Y, which in ((Ks, K, "K"), (Ms, M, "M")):
            if close(X, Y):
                score += per
                n_ok += 1
            else:
                names = [_global_name(k) for k in np.setdiff1d(np.arange(2 * (n + 1)), fixed)]
                fb.append(f"{tag} {which} differs: {_worst_entry(X, Y, names)}; check the element matrices "
                          "of (a) and that overlapping entries are added")
    if n_ok == 2 * len(calls):
        fb.insert(0, "correct: K and M of both beams match")
    return score, fb


def _global_name(k):
    return f"{'theta' if k % 2 else 'w'}{k // 2 + 1}"


# ----------------------------------------------------------------------------
# (c) natural frequencies
# ----------------------------------------------------------------------------

def _check_frequencies(outcomes, calls):
    per = POINTS["c"] / len(calls)
    score, fb, n_ok = 0.0, [], 0
    for call, tag, w in returned(outcomes, calls, fb, as_array, "natural_frequencies()"):
        n, length, E, I, rho, A, support, n_modes = call.args
        d = call.kwargs_ref["d"]
        w = w.ravel()
        if w.size != n_modes:          # before any computation: a huge array is never analysed
            fb.append(f"{tag} expected the {n_modes} lowest frequencies, got {w.size} numbers")
            continue
        ref = frequencies(*supported(n, length, E, d, rho, support), n_modes)
        if close(w, ref):
            score += per
            n_ok += 1
            continue
        msg = None
        K0, M0 = free_free(n, length, E, d, rho)
        if (np.any(~np.isfinite(w)) or np.nanmin(np.abs(w)) < 1e-3 * ref[0]
                or close(w, frequencies(K0, M0, n_modes))):
            msg = ("boundary conditions not applied: you have rigid-body zero frequencies (a free beam has two "
                   "rigid-body modes, at 0 rad/s; rounding turns them into tiny or NaN values)")
        elif close(np.sort(w), ref):
            msg = "the right frequencies, but not in ascending order"
        elif close(w * 2 * np.pi, ref):
            msg = "these are in Hz: return rad/s (omega = 2 pi f)"
        elif close(w, ref**2):
            msg = "these are omega^2 (the eigenvalues): take the square root"
        else:
            other = "cantilever" if support == "pinned" else "pinned"
            alternatives = [
                (frequencies(*reduce(*_lumped_free_free(n, length, E, d, rho), constrained(n, support)), n_modes),
                 "these are the frequencies of a lumped mass matrix; use the consistent mass matrix of (a)"),
                (frequencies(*supported(n, length, E, d, rho, other), n_modes),
                 f"these are the frequencies of a {SUPPORT_TEXT[other]} beam"),
                (frequencies(*supported(n, length * n, E, d, rho, support), n_modes),
                 "every element has the full beam length: an element is length/n_elements long"),
            ]
            for alt, text in alternatives:
                if close(w, alt):
                    msg = text
                    break
        if msg is None:
            k = int(np.nanargmax(np.abs(w - ref) / ref))
            msg = (f"mode {k + 1} is furthest off (yours is {'too high' if w[k] > ref[k] else 'too low'}); "
                   "check (a) and (b) (use scipy.linalg.eigh(K, M))")
        fb.append(f"{tag} {msg}")
    if n_ok == len(calls):
        fb.insert(0, "correct: the frequencies of both beams match")
    return score, fb


# ----------------------------------------------------------------------------
# (d) convergence
# ----------------------------------------------------------------------------

def _errors_match(e, ref):
    return e.shape == ref.shape and bool(np.all(np.abs(e - ref) <= RTOL_ERR * np.abs(ref) + ATOL_ERR))


def _diagnose_errors(e, ref, length, E, d, rho, support, mode, counts=(2, 4, 8)):
    exact = exact_frequency(length, E, d, rho, support, mode)
    w_fe = exact * (1 + ref)
    if np.all(np.isfinite(e)) and np.all(np.abs(e + 1) < 1e-3):
        return ("your finite-element frequency is (nearly) zero: a rigid-body mode, so the boundary conditions "
                "are not applied (see (c))")
    if _errors_match(e, 100 * ref):
        return "these are percentages: return the relative error as a fraction (0.01, not 1 %)"
    if _errors_match(e, -ref / (1 + ref)):
        return "the error has the wrong reference: return (omega_N - omega_exact) / omega_exact"
    if _errors_match(e, w_fe - exact):
        return "this is the absolute error in rad/s: divide by the exact frequency"
    lumped = _lumped_errors(length, E, d, rho, support, mode, exact, counts)
    if lumped is not None and _errors_match(e, lumped):
        return "these are the errors of a lumped mass matrix; use the consistent mass matrix of (a)"
    if np.all(np.isfinite(e)) and np.all(e != -1):
        # the submission's exact value, assuming its finite-element frequencies are right
        r = (1 + ref) / (1 + e)
        if np.all(np.abs(r / r[0] - 1) < 1e-6):
            c = float(r[0])               # omega_exact(submission) / omega_exact
            from mutext.rotor.analytic import beta_l
            bl = [beta_l(support, n) for n in range(1, 7)]
            if abs(c * 2 * np.pi - 1) < 1e-4 or abs(c / (2 * np.pi) - 1) < 1e-4:
                return ("the finite-element and the analytic frequency are in different units (one in Hz, "
                        "one in rad/s)")
            if support == "cantilever" and abs(c - (math.pi * mode / bl[mode - 1]) ** 2) < 1e-4:
                npi = "pi" if mode == 1 else f"{mode} pi"
                return (f"the analytic value uses beta L = {npi}, which is the pinned-pinned value; for a "
                        f"cantilever beta_{mode} L = {bl[mode - 1]:.10f} (a root of cos x cosh x = -1)")
            for m in (mode - 1, mode + 1):
                if 1 <= m <= len(bl) and abs(c - (bl[m - 1] / bl[mode - 1]) ** 2) < 1e-4:
                    return (f"the analytic value is that of mode {m}, not mode {mode} "
                            "(mode numbers start at 1; Python indices at 0)")
            if abs(c - 1) < 1e-2:
                return (f"your analytic frequency is about {_one_digit(abs(c - 1) * 1e6)} ppm off: use beta L to "
                        f"at least 10 digits (beta_{mode} L = {bl[mode - 1]:.12g}); the errors are graded to 0.01 % "
                        "of themselves, so the analytic value must be far more accurate than the finite-element "
                        "one with 8 elements")
            nice = _simple_factor(c)
            return ((f"your analytic frequency is {nice} times the exact one" if nice is not None else
                     "your analytic frequency is off by a constant factor")
                    + ", (beta L)^2 sqrt(EI/(rho A L^4))")
        if np.all(np.abs(e) < np.abs(ref) * 1e-3 + 1e-12):
            return "the errors are (nearly) zero: compare the finite-element value with the exact formula"
        if np.all(e < 0):
            return ("the errors are negative, but with the consistent mass matrix the finite-element frequencies "
                    "lie above the exact ones (a Rayleigh-Ritz upper bound); a lumped mass matrix or a wrong "
                    "analytic value gives negative errors")
    k = int(np.argmax(np.abs(e - ref) / (np.abs(ref) + ATOL_ERR)))
    return (f"N = {counts[k]} is furthest off; the finite-element frequencies (see (c)) or the analytic "
            "value are off")


def _one_digit(x):
    """``x`` rounded to one significant digit, as text (the size of a mistake, not a reference)."""
    if not (math.isfinite(x) and x > 0):
        return fmt(x)
    return f"{round(x, -int(math.floor(math.log10(x)))):g}"


def _lumped_errors(length, E, d, rho, support, mode, exact, counts=(2, 4, 8)):
    """The errors of (d) with a lumped mass matrix, or None where it has fewer than ``mode`` finite modes."""
    out = []
    for n in counts:
        w = frequencies(*reduce(*_lumped_free_free(n, length, E, d, rho), constrained(n, support)))
        if w.size < mode:
            return None
        out.append(w[mode - 1] / exact - 1)
    return np.array(out)


def _check_errors(outcomes, calls):
    per = POINTS["d"] / len(calls)
    score, fb, n_ok = 0.0, [], 0
    for call, tag, e in returned(outcomes, calls, fb, as_array, "relative_errors()"):
        length, E, I, rho, A, support = call.args
        mode = call.kwargs["mode"]
        counts = tuple(call.kwargs["element_counts"])
        d = call.kwargs_ref["d"]
        e = e.ravel()
        if e.size != 3:                # before any computation: a huge array is never analysed
            fb.append(f"{tag} expected 3 relative errors (one per element count asked), got {e.size} numbers")
            continue
        ref = reference_errors(length, E, d, rho, support, mode, counts)
        if _errors_match(e, ref):
            score += per
            n_ok += 1
            continue
        fb.append(f"{tag} " + _diagnose_errors(e, ref, length, E, d, rho, support, mode, counts))
    if n_ok == len(calls):
        orders = []
        for call in calls:
            length, E, I, rho, A, support = call.args
            counts = np.array(call.kwargs["element_counts"], float)
            ref = reference_errors(length, E, call.kwargs_ref["d"], rho, support, call.kwargs["mode"],
                                   tuple(call.kwargs["element_counts"]))
            orders.append(-np.log(ref[-1] / ref[0]) / np.log(counts[-1] / counts[0]))
        fb.insert(0, "correct: all errors match; the error falls about as N^-"
                     f"{np.median(orders):.1f} with the number of elements N (h^4 convergence of cubic elements)")
    return score, fb


# ----------------------------------------------------------------------------

class _Call(Call):
    """A :class:`Call` that also remembers the section diameter for the reference (not sent to the child)."""

    def __init__(self, label, args=(), kwargs=None, d=None):
        super().__init__(label, list(args), dict(kwargs or {}))
        self.kwargs_ref = {"d": d}


def _beam_call(label, n, length, mat, support, *extra, kwargs=None):
    E, I, rho, A = beam_args(mat)
    args = ([n] if n is not None else []) + [length, E, I, rho, A, support, *extra]
    return _Call(label, args, kwargs, d=mat["d"])


def questions(rng=None):
    """The four questions with inputs drawn from ``rng`` (:func:`draw`; a fresh generator if None).

    The labels name the support, the number of elements and the modes asked (arguments, not answers)."""
    cases = draw(np.random.default_rng() if rng is None else rng)
    a_calls = []
    for i, (mat, L) in enumerate(cases["a"]):
        E, I, rho, A = beam_args(mat)
        a_calls.append(_Call(f"element {i + 1} of {len(cases['a'])}", [E, I, rho, A, L], d=mat["d"]))
    b_calls = [_beam_call(f"beam {i + 1} of {len(cases['b'])}: {SUPPORT_TEXT[sup]}, {n} elements", n, length, mat,
                          sup) for i, (n, length, mat, sup) in enumerate(cases["b"])]
    c_calls = [_beam_call(f"beam {i + 1} of {len(cases['c'])}: {SUPPORT_TEXT[sup]}, {n} elements, {k} modes", n,
                          length, mat, sup, k) for i, (n, length, mat, sup, k) in enumerate(cases["c"])]
    d_calls = [_beam_call(f"beam {i + 1} of {len(cases['d'])}: {SUPPORT_TEXT[sup]}, mode {mode}, "
                          f"N = {', '.join(map(str, counts))}", None, length, mat, sup,
                          kwargs={"mode": mode, "element_counts": list(counts)})
               for i, (length, mat, sup, mode, counts) in enumerate(cases["d"])]
    return [
        Question("a", "element_matrices", "element stiffness and consistent mass matrices", POINTS["a"], "array",
                 a_calls, lambda oc: _check_element(oc, a_calls)),
        Question("b", "assemble", "global matrices with supports", POINTS["b"], "array", b_calls,
                 lambda oc: _check_assembly(oc, b_calls)),
        Question("c", "natural_frequencies", "natural frequencies in rad/s", POINTS["c"], "array", c_calls,
                 lambda oc: _check_frequencies(oc, c_calls)),
        Question("d", "relative_errors", "convergence against the exact frequency", POINTS["d"], "array",
                 d_calls, lambda oc: _check_errors(oc, d_calls)),
    ]


EXERCISE = Exercise("ex04_beam_element", "Euler-Bernoulli beam elements: assembly, frequencies, convergence",
                    questions, stub="exercises/ex04_beam_element.py", prepare=prepare,
                    blocked_modules=("mutext.rotor",))
