"""The public description of the exercises in ``exercises/``: what each function receives and returns.

Every exercise lists its questions with the function a student writes, the
kind of value it returns (``"ss"``, ``"float"`` or ``"array"``, as the
confined child sends it back), a sentence on the expected shape, and two
callables:

``sample_calls(rng)``
    A list of ``(args, kwargs)`` with JSON-ready arguments, drawn afresh from
    the numpy ``Generator`` ``rng`` with plain numpy and public library
    functions (a random two-mass system, a simulated free decay, a random
    chain of masses, a synthetic rotor sweep).  These are *plausible* inputs
    of the right form, never the graded ones, and nothing here computes an
    answer to them.
``shape_problem(value, args, kwargs)``
    ``None`` when a returned value (as the sandbox sends it back) has the
    kind and shape the exercise asks for, else one sentence saying what was
    expected.  Shape rules are those of the docstrings (an array of 3
    numbers, a StateSpace with 2 inputs and 2 outputs, a square pair of
    matrices of size ``2N``); whether the numbers are right is the grader's
    business, which is not part of this package.

Used by :mod:`mutext.grading.check` (``mutext check EXERCISE FILE``).  The
instructor's grader (``mutext_grader``) has its own, secret, inputs and
reference answers; the tests check that the ids, functions, kinds, points
and blocked modules here agree with it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ._shape import array_rule, float_rule, ss_rule

__all__ = ["QuestionSpec", "ExerciseSpec", "EXERCISES", "get_exercise", "find_exercise", "UnknownExercise"]


@dataclass(frozen=True)
class QuestionSpec:
    """One graded function of an exercise.

    Attributes
    ----------
    id : str
        Question id (e.g. ``"q1"``).
    function : str
        Name of the function students write.
    title : str
        The question in words.
    points : float
        Points it carries.
    kind : str
        ``"ss"``, ``"float"`` or ``"array"``: what the child sends back.
    returns : str
        The expected return, in words (shape rules).
    sample_calls : callable
        ``sample_calls(rng)`` -> list of ``(args, kwargs)``, JSON-ready.
    shape_problem : callable
        ``shape_problem(value, args, kwargs)`` -> None, or what was expected.
    """
    id: str
    function: str
    title: str
    points: float
    kind: str                     # "ss", "float" or "array": what the child sends back
    returns: str                  # the expected return, in words (shape rules)
    sample_calls: Callable        # (rng) -> list of (args, kwargs), JSON-ready
    shape_problem: Callable       # (value, args, kwargs) -> None or what was expected


@dataclass(frozen=True)
class ExerciseSpec:
    """One exercise: its file, its graded functions and what the submission may not import.

    Attributes
    ----------
    name : str
        Name of the exercise (e.g. ``"ex01_star"``).
    title : str
        Its title.
    description : str
        What it asks, in words.
    stub : str
        The file students fill in, relative to the repository.
    blocked_modules : tuple of str
        Library modules the submission may not import (they compute the answers).
    questions : tuple of QuestionSpec
        The graded functions.
    """
    name: str
    title: str
    description: str
    stub: str                     # the file students fill in, relative to the repository
    blocked_modules: tuple = ()   # library modules the submission may not import (they compute answers)
    questions: tuple = field(default_factory=tuple)

    @property
    def points(self) -> float:
        return float(sum(q.points for q in self.questions))

    def question(self, qid: str) -> QuestionSpec:
        """The question with id ``qid``.

        Parameters
        ----------
        qid : str
            Question id.
        """
        return next(q for q in self.questions if q.id == qid)


class UnknownExercise(LookupError):
    """No exercise of that name (or several start with it).

    Parameters
    ----------
    name : str
        The name asked for.
    """

    def __init__(self, name):
        self.name = name
        super().__init__(f"unknown exercise '{name}'. Available: {', '.join(EXERCISES)}")


# ----------------------------------------------------------------------------------------------------------
# small helpers for the sample inputs
# ----------------------------------------------------------------------------------------------------------

def _u(rng, lo, hi, digits=4):
    """A uniform draw rounded to ``digits`` significant digits (readable inputs)."""
    x = float(rng.uniform(lo, hi))
    return float(f"{x:.{digits}g}")


def _lists(X):
    return np.asarray(X, dtype=float).tolist()


def _ss_arg(A, B, C, D):
    return {"__ss__": [_lists(A), _lists(B), _lists(C), _lists(D)]}


def _stable(rng, n):
    """A random stable ``n x n`` matrix (eigenvalues shifted left of -0.2)."""
    A = rng.standard_normal((n, n))
    return A - (np.linalg.eigvals(A).real.max() + rng.uniform(0.2, 1.5)) * np.eye(n)


def _complex_matrix(rng, n):
    return rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))


def _split(M):
    M = np.asarray(M, dtype=complex)
    return [M.real.tolist(), M.imag.tolist()]


# ----------------------------------------------------------------------------------------------------------
# ex01: H-infinity control of the two-mass system
# ----------------------------------------------------------------------------------------------------------

def _two_masses(rng):
    return [_u(rng, 0.5, 3.0), _u(rng, 0.5, 3.0), _u(rng, 100.0, 1000.0), _u(rng, 50.0, 600.0)]


def _ex01_a(rng):
    return [(_two_masses(rng), {}) for _ in range(2)]


def _ex01_b(rng):
    m1, m2, k1, k2 = _two_masses(rng)
    full = dict(m1=m1, m2=m2, k1=k1, k2=k2, f_max=_u(rng, 1.0, 20.0), eta_max=_u(rng, 5e-5, 5e-4),
                x_max=_u(rng, 0.01, 0.05), u_max=_u(rng, 20.0, 100.0))
    part = dict(f_max=_u(rng, 1.0, 20.0), x_max=_u(rng, 0.01, 0.05))     # the others stay at their defaults
    return [([], full), ([], part)]


def _ex01_c(rng):
    calls = []
    wn, z = _u(rng, 2.0, 50.0), _u(rng, 0.002, 0.05)
    calls.append(([_ss_arg([[0.0, 1.0], [-wn * wn, -2 * z * wn]], [[0.0], [wn * wn]], [[1.0, 0.0]], [[0.0]])], {}))
    for n, p, m in ((1, 1, 1), (int(rng.integers(2, 5)), 2, 2)):
        calls.append(([_ss_arg(_stable(rng, n), rng.standard_normal((n, m)), rng.standard_normal((p, n)),
                               0.3 * rng.standard_normal((p, m)))], {}))
    return calls


def _ex01_d(rng):
    return [([], {})]


EX01 = ExerciseSpec(
    "ex01_two_mass_hinf", "H-infinity control of the two-mass system",
    "two-mass system: mechanical model, generalized plant, H-infinity norm, controller",
    "exercises/ex01_two_mass_hinf.py", (),
    (QuestionSpec("a", "mechanical_model", "state-space model of the two masses", 2.0, "ss",
                  "StateSpace (continuous time) with 2 inputs [f_e, u] and 2 outputs [x1, x2]", _ex01_a,
                  ss_rule(2, 2)),
     QuestionSpec("b", "generalized_plant", "generalized plant with weights", 3.0, "ss",
                  "StateSpace (continuous time) with 3 inputs [f1, f2, u] and 3 outputs [z1, z2, y]", _ex01_b,
                  ss_rule(3, 3)),
     QuestionSpec("c", "hinf_norm", "H-infinity norm", 2.0, "float", "float (finite)", _ex01_c, float_rule()),
     QuestionSpec("d", "controller", "H-infinity controller", 3.0, "ss",
                  "StateSpace (continuous time) with 1 input y and 1 output u", _ex01_d, ss_rule(1, 1))))


# ----------------------------------------------------------------------------------------------------------
# ex02: the structured singular value
# ----------------------------------------------------------------------------------------------------------

def _ex02_matrices(rng, sizes):
    return [(_split(_complex_matrix(rng, n)), {}) for n in sizes]


def _ex02_a(rng):
    return _ex02_matrices(rng, (2, 3, int(rng.integers(2, 5))))


def _ex02_b(rng):
    return _ex02_matrices(rng, (2, 3))


def _ex02_c(rng):
    return [([_u(rng, 0.2, 5.0), _u(rng, 100.0, 5e4), _u(rng, 0.05, 0.5)], {}) for _ in range(2)]


def _ex02_d(rng):
    calls = []
    for n in (2, 3):
        N = int(rng.integers(20, 41))
        A, B, C = _stable(rng, n + 1), rng.standard_normal((n + 1, n)), rng.standard_normal((n, n + 1))
        w = np.logspace(-1, 1.5, N)
        G = np.stack([C @ np.linalg.solve(1j * wi * np.eye(n + 1) - A, B) for wi in w])
        calls.append((_split(G), {}))
    return calls


def _n_of_first(args, kwargs):
    return len(args[0])


EX02 = ExerciseSpec(
    "ex02_mu", "The structured singular value: bounds, destabilising Delta, uncertain LFT",
    "structured singular value: full-block mu, D-scaling upper bound, destabilising Delta, uncertain spring "
    "as an LFT, peak over frequency",
    "exercises/ex02_mu.py", ("mutext.mu", "mutext.uncertain", "mutext.dk"),
    (QuestionSpec("a1", "mu_full", "mu for one full complex block", 1.0, "float", "float (finite)", _ex02_a,
                  float_rule()),
     QuestionSpec("a2", "mu_scalar_blocks_upper", "D-scaling upper bound for scalar blocks", 2.0, "float",
                  "float (finite)", _ex02_a, float_rule()),
     QuestionSpec("b", "destabilizing_delta", "smallest destabilising diagonal Delta", 2.0, "array",
                  "(Delta.real, Delta.imag): array of shape (2, n, n) for an n x n M", _ex02_b,
                  array_rule(shape=lambda a, k: (2, _n_of_first(a, k), _n_of_first(a, k)),
                             alternatives=lambda a, k: [(2, _n_of_first(a, k))])),
     QuestionSpec("c", "uncertain_spring_lft", "uncertain spring as an upper LFT", 3.0, "ss",
                  "StateSpace or (A, B, C, D), continuous time, with 2 inputs [w, f] and 2 outputs [z, x]",
                  _ex02_c, ss_rule(2, 2)),
     QuestionSpec("d", "mu_peak", "peak of the upper bound over frequency", 2.0, "float", "float (finite)",
                  _ex02_d, float_rule())))


# ----------------------------------------------------------------------------------------------------------
# ex03: free-decay identification of a cart
# ----------------------------------------------------------------------------------------------------------

def _cart(rng):
    """``(m, k, c)`` of a plausible cart: 20 to 60 rad/s, damping ratio 0.5 % to 10 %."""
    m, wn, z = _u(rng, 0.5, 3.0), _u(rng, 20.0, 60.0), _u(rng, 0.005, 0.1)
    return m, float(f"{m * wn * wn:.5g}"), float(f"{2 * z * m * wn:.4g}")


def _decay(m, k, c, noise=0.0, seed=None):
    from mutext.sysid import simulate_free_decay
    t, y = simulate_free_decay(m, k, c, x0=0.025, duration=3.0, fs=1000.0, noise=noise, rng=seed)
    return np.round(t, 6).tolist(), y.tolist()


def _ex03_a(rng):
    calls = []
    for _ in range(2):
        m, k, c = _cart(rng)
        t, y = _decay(m, k, c)
        calls.append(([t, y, int(rng.integers(3, 7))], {}))
    return calls


def _ex03_b1(rng):
    out = []
    for _ in range(2):
        m, k, _ = _cart(rng)
        mw = _u(rng, 0.5, 3.0)
        out.append(([float(f"{math.sqrt(k / m):.6g}"), float(f"{math.sqrt(k / (m + mw)):.6g}"), mw], {}))
    return out


def _ex03_b2(rng):
    return [([_u(rng, 15.0, 60.0), _u(rng, 0.5, 3.0)], {}) for _ in range(2)]


def _ex03_c(rng):
    return [([_u(rng, 0.005, 0.1), _u(rng, 0.5, 3.0), _u(rng, 15.0, 60.0)], {}) for _ in range(2)]


def _ex03_d(rng):
    m, k, c = _cart(rng)
    mw = _u(rng, 0.5, 2.0)
    seeds = rng.integers(0, 2 ** 31, size=2)
    t0, y0 = _decay(m, k, c, 3e-6, int(seeds[0]))
    t1, y1 = _decay(m + mw, k, c, 3e-6, int(seeds[1]))
    return [([t0, y0, t1, y1, mw], {})]


_FLOAT = "float (finite)"

EX03 = ExerciseSpec(
    "ex03_free_decay", "Free-decay identification of a cart: frequency, damping, mass, stiffness",
    "free-decay identification of a cart: frequency, damping ratio, mass, stiffness, damping coefficient",
    "exercises/ex03_free_decay.py", ("mutext.sysid", "mutext.examples"),
    (QuestionSpec("a1", "natural_frequency", "frequency from peak times, eq. 3.1 (rad/s)", 1.5, "float", _FLOAT,
                  _ex03_a, float_rule()),
     QuestionSpec("a2", "damping_ratio", "damping ratio from the log decrement, eq. 3.2", 1.5, "float", _FLOAT,
                  _ex03_a, float_rule()),
     QuestionSpec("b1", "cart_mass", "cart mass from the added mass, eq. 3.3", 1.5, "float", _FLOAT, _ex03_b1,
                  float_rule()),
     QuestionSpec("b2", "stiffness", "equivalent stiffness, eq. 3.4", 1.5, "float", _FLOAT, _ex03_b2, float_rule()),
     QuestionSpec("c", "damping_coefficient", "damping coefficient, eq. 3.5", 2.0, "float", _FLOAT, _ex03_c,
                  float_rule()),
     QuestionSpec("d", "identify_cart", "(m_c, k, c) from a bare and a weighted decay", 2.0, "array",
                  "array of 3 numbers [m_c, k, c]", _ex03_d, array_rule(size=lambda a, k: 3))))


# ----------------------------------------------------------------------------------------------------------
# ex04: Euler-Bernoulli beam elements
# ----------------------------------------------------------------------------------------------------------

def _beam(rng):
    """``(E, I, rho, A)`` of a solid circular section of a random metal."""
    E, rho, d = _u(rng, 6e10, 2.2e11), _u(rng, 2500.0, 8000.0), _u(rng, 0.01, 0.05)
    return E, math.pi * d ** 4 / 64.0, rho, math.pi * d ** 2 / 4.0


def _support(rng):
    return str(rng.choice(["pinned", "cantilever"]))


def _ex04_a(rng):
    return [([*_beam(rng), _u(rng, 0.05, 2.5)], {}) for _ in range(2)]


def _ex04_b(rng):
    return [([int(n), _u(rng, 0.3, 2.0), *_beam(rng), s], {})
            for n, s in ((rng.integers(2, 6), "pinned"), (rng.integers(2, 6), "cantilever"))]


def _ex04_c(rng):
    out = []
    for s in ("pinned", "cantilever"):
        n = int(rng.integers(2, 7))
        out.append(([n, _u(rng, 0.3, 2.0), *_beam(rng), s, int(rng.integers(1, min(2 * n, 5) + 1))], {}))
    return out


def _ex04_d(rng):
    # the element counts are drawn as the grader draws its own (three increasing counts up to 8)
    def counts():
        a = int(rng.integers(2, 4))
        b = int(rng.integers(a + 1, 6))
        return [a, b, int(rng.integers(max(b + 1, 5), 9))]
    return [([_u(rng, 0.3, 2.0), *_beam(rng), _support(rng)], {"mode": int(mode), "element_counts": counts()})
            for mode in (1, 2)]


EX04 = ExerciseSpec(
    "ex04_beam_element", "Euler-Bernoulli beam elements: assembly, frequencies, convergence",
    "Euler-Bernoulli beam elements: element matrices, assembly, natural frequencies, convergence",
    "exercises/ex04_beam_element.py", ("mutext.rotor",),
    (QuestionSpec("a", "element_matrices", "element stiffness and consistent mass matrices", 3.0, "array",
                  "(K, M): two 4 x 4 matrices, an array of shape (2, 4, 4)", _ex04_a,
                  array_rule(shape=lambda a, k: (2, 4, 4))),
     QuestionSpec("b", "assemble", "global matrices with supports", 2.0, "array",
                  "(K, M): two square matrices of size 2N (N = n_elements), an array of shape (2, 2N, 2N)",
                  _ex04_b, array_rule(shape=lambda a, k: (2, 2 * int(a[0]), 2 * int(a[0])))),
     QuestionSpec("c", "natural_frequencies", "natural frequencies in rad/s", 2.0, "array",
                  "array of n_modes numbers", _ex04_c, array_rule(size=lambda a, k: int(a[7]))),
     QuestionSpec("d", "relative_errors", "convergence against the exact frequency", 3.0, "array",
                  "array of 3 numbers (one per element count asked)", _ex04_d, array_rule(size=lambda a, k: 3))))


# ----------------------------------------------------------------------------------------------------------
# ex05: find the effect hidden in measured FRFs
# ----------------------------------------------------------------------------------------------------------

def _chain(rng):
    """``(M, C, K, f_hz)`` of a random grounded chain of 3 or 4 masses and a grid around its resonances."""
    n = int(rng.integers(3, 5))
    m = np.array([_u(rng, 0.5, 2.0) for _ in range(n)])
    k = np.array([_u(rng, 300.0, 3000.0) for _ in range(n)])
    K = np.zeros((n, n))
    K[0, 0] = k[0]                                       # the first spring ties mass 1 to the ground
    for i in range(1, n):
        K[i - 1:i + 1, i - 1:i + 1] += k[i] * np.array([[1.0, -1.0], [-1.0, 1.0]])
    M = np.diag(m)
    C = _u(rng, 5e-4, 2e-3) * K + _u(rng, 0.05, 0.5) * M
    fn = np.sqrt(np.linalg.eigvals(np.linalg.solve(M, K)).real) / (2 * np.pi)
    f = np.round(np.linspace(0.5 * fn.min(), 1.4 * fn.max(), 200), 6)
    return M, C, K, f


def _receptance(M, C, K, f, i, o):
    w = 2 * np.pi * np.asarray(f)
    e = np.zeros(M.shape[0])
    e[i] = 1.0
    return np.array([np.linalg.solve(K - wi * wi * M + 1j * wi * C, e)[o] for wi in w])


def _noisy(rng, h, noise=0.01):
    return h * (1 + noise * (rng.standard_normal(h.size) + 1j * rng.standard_normal(h.size)) / math.sqrt(2))


def _changed(M, C, K, kind, dof, size):
    M, C, K = M.copy(), C.copy(), K.copy()
    if kind != "none":
        {"stiffness": K, "mass": M, "damping": C}[kind][dof, dof] += size
    return M, C, K


def _ex05_a(rng):
    out = []
    for _ in range(2):
        M, C, K, f = _chain(rng)
        n = M.shape[0]
        h = _receptance(M, C, K, f, int(rng.integers(n)), int(rng.integers(n)))
        d = _noisy(rng, h, _u(rng, 0.005, 0.05))
        out.append(([h.real.tolist(), h.imag.tolist(), d.real.tolist(), d.imag.tolist()], {}))
    return out


def _ex05_b(rng):
    out = []
    for _ in range(2):
        M, C, K, f = _chain(rng)
        n = M.shape[0]
        out.append(([_lists(M), _lists(C), _lists(K), f[::4].tolist(), int(rng.integers(n)), int(rng.integers(n)),
                     int(rng.integers(n)), _u(rng, 50.0, 1000.0)], {}))
    return out


def _ex05_c(rng):
    M, C, K, f = _chain(rng)
    n = M.shape[0]
    i, o, dof = int(rng.integers(n)), int(rng.integers(n)), int(rng.integers(n))
    d = _noisy(rng, _receptance(*_changed(M, C, K, "stiffness", dof, _u(rng, 50.0, 1000.0)), f, i, o))
    return [([_lists(M), _lists(C), _lists(K), f.tolist(), i, o, d.real.tolist(), d.imag.tolist(), dof], {})]


def _ex05_d(rng):
    M, C, K, f = _chain(rng)
    n = M.shape[0]
    kind = str(rng.choice(["none", "stiffness", "mass", "damping"]))
    size = {"none": 0.0, "stiffness": _u(rng, 100.0, 800.0), "mass": _u(rng, 0.1, 0.5),
            "damping": _u(rng, 1.0, 5.0)}[kind]
    changed = _changed(M, C, K, kind, int(rng.integers(n)), size)
    i = int(rng.integers(n))
    chans = [[i, o] for o in range(n)]
    data = [_noisy(rng, _receptance(*changed, f, a, b)) for a, b in chans]
    return [([_lists(M), _lists(C), _lists(K), f.tolist(), chans, [d.real.tolist() for d in data],
              [d.imag.tolist() for d in data], 0.01], {})]


def _effect_format(arr):
    kind, station = float(arr.ravel()[0]), float(arr.ravel()[1])
    if not (kind.is_integer() and 0 <= kind <= 3):
        return "the first number must be the index of the kind in KINDS (0, 1, 2 or 3)"
    if not (station.is_integer() and station >= 0):
        return "the second number must be the 1-based mass (an integer; 0 for \"none\")"
    return None


EX05 = ExerciseSpec(
    "ex05_diagnose", "Diagnosis: find the effect hidden in measured frequency responses",
    "diagnosis: log misfit, a grounded spring added, its size fitted, a hidden effect found",
    "exercises/ex05_diagnose.py",
    ("mutext.diagnose", "mutext.hide", "mutext.rotor", "mutext.mbi", "mutext.report", "mutext.commands"),
    (QuestionSpec("a", "log_misfit", "RSS of the complex log ratio", 1.5, "float", _FLOAT, _ex05_a, float_rule()),
     QuestionSpec("b", "response_with_grounded_spring", "response with an added grounded spring", 2.0, "array",
                  "array of shape (2, len(f_hz)): real parts, imaginary parts", _ex05_b,
                  array_rule(shape=lambda a, k: (2, len(a[3])))),
     QuestionSpec("c", "fit_grounded_spring", "size of a hidden grounded spring", 2.0, "float", _FLOAT, _ex05_c,
                  float_rule()),
     QuestionSpec("d", "find_effect", "kind, place and size of a hidden effect", 4.5, "array",
                  "array of 3 numbers [KINDS.index(kind), station, size]", _ex05_d,
                  array_rule(size=lambda a, k: 3, check=_effect_format))))


# ----------------------------------------------------------------------------------------------------------
# ex06: sidebands of a cracked rotor at speed
# ----------------------------------------------------------------------------------------------------------

def _rotor_modes(rng):
    """Natural frequencies [Hz] of a rotor bending in two planes: two pairs inside 20-225 Hz, one above."""
    out = []
    for lo, hi in ((30.0, 45.0), (150.0, 200.0), (330.0, 380.0)):
        f = _u(rng, lo, hi, 6)
        out += [f, float(f"{f * (1 + rng.uniform(0.0, 0.02)):.6g}")]
    return out


def _sweep(rng, fn, speed, orders, noise):
    """A synthetic receptance sweep 20-225 Hz in 0.5 Hz steps: the modes ``fn``, small extra resonances at
    ``f_n - k speed`` for ``|k|`` in ``orders``, relative complex noise."""
    f = np.arange(20.0, 225.25, 0.5)
    H = np.zeros(f.size, complex)
    for fi in fn:
        H += 1e-4 / (fi * fi - f * f + 2j * 0.01 * fi * f)
    bump = np.ones(f.size, complex)
    for fi in fn[::2]:
        for k in orders:
            for s in (1, -1):
                fs = fi - s * k * speed
                bump += rng.uniform(2e-3, 6e-3) / (1 + 2j * (f - fs) / 0.4)
    H = H * bump
    H = _noisy(rng, H, noise)
    return f.tolist(), H.real.tolist(), H.imag.tolist()


def _ex06_a(rng):
    out = []
    for orders in ([1, 2, 3], [2]):
        fn = sorted(_u(rng, 20.0, 400.0, 6) for _ in range(int(rng.integers(2, 6))))
        lo = _u(rng, 10.0, 60.0)
        out.append(([fn, _u(rng, 5.0, 20.0), orders, lo, float(f"{lo + rng.uniform(100.0, 300.0):.4g}")], {}))
    return out


def _ex06_b(rng):
    out = []
    for orders in ([1, 2, 3], []):
        fn, speed = _rotor_modes(rng), _u(rng, 8.0, 12.0)
        f, re, im = _sweep(rng, fn, speed, orders, 5e-4)
        k = int(rng.choice([1, 2]))
        out.append(([f, re, im, float(f"{fn[2] - k * speed:.6g}"), 3.0], {}))
    return out


def _ex06_c(rng):
    out = []
    for orders in ([1, 2, 3], [2], []):
        fn, speed = _rotor_modes(rng), _u(rng, 8.0, 12.0)
        noise = float(rng.choice([5e-4, 1e-3]))
        f, re, im = _sweep(rng, fn, speed, orders, noise)
        out.append(([f, re, im, fn, speed, noise], {}))
    return out


EX06 = ExerciseSpec(
    "ex06_sidebands", "Sidebands: predict and find the sidebands of a cracked rotor at speed",
    "cracked rotor at speed: where sidebands appear, a local sideband detector, breathing crack, open crack "
    "or none",
    "exercises/ex06_sidebands.py",
    ("mutext.diagnose", "mutext.rotor", "mutext.rig", "mutext.report", "mutext.commands"),
    (QuestionSpec("a", "sideband_frequencies", "where the sidebands must appear", 2.5, "array",
                  "1-D array of numbers (any length, possibly empty)", _ex06_a, array_rule(vector=True)),
     QuestionSpec("b", "sideband_size", "size of a local departure from a smooth baseline", 2.5, "float", _FLOAT,
                  _ex06_b, float_rule()),
     QuestionSpec("c", "classify", "once per revolution, twice per revolution or none", 5.0, "float",
                  "VERDICTS.index(verdict): 0, 1 or 2", _ex06_c, float_rule(choices=(0, 1, 2)))))


# ----------------------------------------------------------------------------------------------------------
# ex07: the M-Delta loop and the small-gain theorem
# ----------------------------------------------------------------------------------------------------------

def _collocated_controller(rng):
    """A first-order controller ``-(kp + kd s)/(1 + tau s)`` as an ``__ss__`` argument (no answer in it)."""
    kp, kd, tau = _u(rng, 0.0, 100.0), _u(rng, 2.0, 20.0), _u(rng, 0.002, 0.02)
    return _ss_arg([[-1.0 / tau]], [[1.0]], [[-(kp - kd / tau) / tau]], [[-kd / tau]])


def _ex07_a(rng):
    return [([_u(rng, 0.5, 3.0), _u(rng, 0.5, 3.0), _u(rng, 200.0, 800.0), _u(rng, 100.0, 600.0),
              _u(rng, 0.05, 0.4), _u(rng, 0.05, 0.4), _collocated_controller(rng)], {}) for _ in range(2)]


def _random_m(rng):
    n = int(rng.integers(3, 6))
    return _ss_arg(_stable(rng, n), rng.standard_normal((n, 2)), rng.standard_normal((2, n)), np.zeros((2, 2)))


def _ex07_b(rng):
    return [([_random_m(rng)], {}) for _ in range(2)]


def _ex07_c(rng):
    return [([_random_m(rng), _u(rng, 0.5, 50.0)], {}) for _ in range(2)]


def _ex07_d(rng):
    out = []
    for _ in range(2):
        Ms = np.stack([_complex_matrix(rng, 2) for _ in range(int(rng.integers(5, 30)))])
        out.append(([Ms.real.tolist(), Ms.imag.tolist()], {}))
    return out


EX07 = ExerciseSpec(
    "ex07_small_gain", "The M-Delta loop: small gain, destabilising Delta, structured mu",
    "M-Delta loop: M = F_l(P, K) of the two-mass springs, H-infinity norm and small-gain margin, least "
    "destabilising Delta, mu bounds for a diagonal structure",
    "exercises/ex07_small_gain.py", ("mutext.mu", "mutext.uncertain", "mutext.dk", "mutext.mbi"),
    (QuestionSpec("a", "m_delta", "the M of the M-Delta loop", 3.0, "ss",
                  "StateSpace or (A, B, C, D), continuous time, with 2 inputs [w1, w2] and 2 outputs [z1, z2]",
                  _ex07_a, ss_rule(2, 2)),
     QuestionSpec("b", "small_gain", "H-infinity norm, peak frequency and small-gain margin", 2.5, "array",
                  "array of 3 numbers [norm, omega_peak (rad/s), margin]", _ex07_b, array_rule(size=lambda a, k: 3)),
     QuestionSpec("c", "destabilizing_delta", "least destabilising full complex Delta", 2.0, "array",
                  "(Delta.real, Delta.imag): array of shape (2, 2, 2)", _ex07_c,
                  array_rule(shape=lambda a, k: (2, 2, 2))),
     QuestionSpec("d", "structured_mu", "mu bounds for the diagonal structure", 2.5, "array",
                  "array of 2 numbers [lower, upper]", _ex07_d, array_rule(size=lambda a, k: 2))))


# ----------------------------------------------------------------------------------------------------------
# ex08: model-based identification on the three-mass rig
# ----------------------------------------------------------------------------------------------------------

def _three_mass_rig(rng):
    """A plausible rig dictionary (three carts, one changed parameter on cart 3, ports, weights)."""
    true = [_u(rng, 2.0, 3.0), _u(rng, 2.0, 3.0), _u(rng, 1.5, 3.0), _u(rng, 300.0, 900.0), _u(rng, 300.0, 900.0),
            _u(rng, 150.0, 500.0), _u(rng, 1.0, 5.0), _u(rng, 1.0, 5.0), _u(rng, 5.0, 15.0)]
    changed = str(rng.choice(["k3", "m3", "c3"]))
    eng = list(true)
    i = {"m3": 2, "k3": 5, "c3": 8}[changed]
    eng[i] = float(f"{true[i] * rng.uniform(0.4, 0.8):.4g}")
    return dict(true=true, engineering=eng, changed=changed, rel=_u(rng, 0.01, 0.03, 3), excitation=0,
                measurement=0, control=2, Ww=1.0, eps_u=_u(rng, 0.05, 0.5, 3), eps_y=_u(rng, 1e-8, 1e-7, 3))


def _ex08_grid(rng):
    return np.round(np.logspace(-0.4, 2.5, int(rng.integers(60, 121))), 8).tolist()


def _ex08_a(rng):
    out = []
    for _ in range(2):
        rig = _three_mass_rig(rng)
        rig.update(excitation=int(rng.integers(3)), measurement=int(rng.integers(3)), control=int(rng.integers(1, 3)))
        out.append(([rig, _u(rng, 1e-4, 2e-3)], {}))
    return out


def _ex08_b(rng):
    return [([_three_mass_rig(rng), _u(rng, 1e-3, 5e-3), _ex08_grid(rng)], {})]


def _ex08_c(rng):
    return [([_three_mass_rig(rng), _u(rng, 1e-4, 3e-4), _u(rng, 2e-3, 5e-3), _ex08_grid(rng)], {})]


def _ex08_d(rng):
    p = _u(rng, 50.0, 300.0)
    K = _ss_arg([[-p, 0.0], [1.0, -p]], [[1.0], [0.0]], [[0.0, _u(rng, 1e5, 1e7)]], [[0.0]])
    return [([_three_mass_rig(rng), _u(rng, 1e-4, 1e-3), K, _ex08_grid(rng)], {})]


EX08 = ExerciseSpec(
    "ex08_mbi", "Model-based identification on the three-mass rig: plant, D-K, the W_z rule, K",
    "model-based identification on the three-mass rig: the plant of Fig. 3.3, D-K, the W_z rule, K read as "
    "mass, damper and spring on its identifiable band",
    "exercises/ex08_mbi.py", ("mutext.mbi", "mutext.diagnose", "mutext.hide", "mutext.commands"),
    (QuestionSpec("a", "mbi_plant", "the plant of thesis Fig. 3.3", 3.0, "ss",
                  "StateSpace or (A, B, C, D), continuous time, with 4 inputs [w_unc, w, n, u] and 4 outputs "
                  "[z_unc, z, z_u, y]", _ex08_a, ss_rule(4, 4)),
     QuestionSpec("b", "synthesize", "D-K: a controller with mu <= 1", 3.0, "ss",
                  "StateSpace, continuous time, with 1 input (y) and 1 output (u)", _ex08_b, ss_rule(1, 1)),
     QuestionSpec("c", "smallest_wz", "the W_z rule: the smallest Wz with mu <= 1", 2.0, "float", _FLOAT, _ex08_c,
                  float_rule()),
     QuestionSpec("d", "read_controller", "K read as mass, damper and spring on its identifiable band", 2.0,
                  "array", "array of 5 numbers [dm, dc, dk, omega_lo, omega_hi]", _ex08_d,
                  array_rule(size=lambda a, k: 5))))


#: name -> ExerciseSpec, in course order
EXERCISES = {ex.name: ex for ex in (EX01, EX02, EX03, EX04, EX05, EX06, EX07, EX08)}


def find_exercise(name: str) -> str | None:
    """The full name of the exercise ``name`` (or the only one starting with it, e.g. ``ex01``), or None.

    Parameters
    ----------
    name : str
        Full name or a unique prefix.
    """
    found = [n for n in EXERCISES if n == name] or [n for n in EXERCISES if name and n.startswith(name)]
    return found[0] if len(found) == 1 else None


def get_exercise(name: str) -> ExerciseSpec:
    """The exercise called ``name`` (a unique prefix such as ``ex01`` works); :class:`UnknownExercise` else.

    Parameters
    ----------
    name : str
        Full name or a unique prefix.
    """
    full = find_exercise(name)
    if full is None:
        raise UnknownExercise(name)
    return EXERCISES[full]
