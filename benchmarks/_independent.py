"""Closed-loop verdicts for the benchmarks that do not rest on mutext's own numerics.

A benchmark that ranks mutext against other tools must not judge every tool
with mutext's frequency responses and stability tests: an error there would
move every verdict at once.  This module judges a controller with other code:

* the loop is closed by python-control (:meth:`control.StateSpace.lft`);
* stability is decided from the closed-loop eigenvalues computed in extended
  precision (``mpmath.eig`` at 40 digits on the balanced A; LAPACK in double
  precision above 40 states, where mpmath takes minutes); a pole counts as
  unstable when its real part is positive by more than a margin relative to
  its own magnitude, so that a stiff loop (poles from 1e-6 to 1e8 rad/s) is
  judged pole by pole;
* frequency responses come from a dense complex LU solve per frequency
  (``numpy.linalg.solve`` of ``(jwI - A) X = B``), which stays accurate where
  Hessenberg-based evaluations lose digits on widely scaled loops;
* mu is SLICOT's AB13MD upper bound (mixed real/complex D-G scalings) on a
  dense grid, with its local peaks refined by golden-section search;
* mixed mu of one matrix with real scalars and one full complex block is
  computed by brute force from the main loop theorem (:func:`mixed_mu_brute_force`).

Each function says what it used, so that a benchmark table can print it.
"""
from __future__ import annotations

import itertools
import math

import control as ct
import mpmath
import numpy as np
import scipy.linalg as sla
from scipy.optimize import brentq, minimize
from slycot import ab13md

USED = ("loop: python-control StateSpace.lft; poles: mpmath.eig (40 digits) of the balanced A "
        "(LAPACK above 40 states); "
        "responses: dense complex LU per frequency; mu: SLICOT AB13MD, peaks refined by golden section")


def closed_loop(P, K, nmeas: int, ncon: int) -> ct.StateSpace:
    """Lower LFT of plant ``P`` with controller ``K`` by python-control."""
    return ct.ss(P).lft(ct.ss(K), nu=ncon, ny=nmeas)


#: above this many states mpmath's eigenvalue solver takes minutes: LAPACK on the balanced A instead
MP_MAX_STATES = 40


def poles(sys, dps: int = 40) -> np.ndarray:
    """Eigenvalues of ``sys.A`` in extended precision (after a similarity balancing);
    above :data:`MP_MAX_STATES` states in double precision (LAPACK, balanced)."""
    A = np.asarray(ct.ss(sys).A, float)
    if A.size == 0:
        return np.zeros(0, complex)
    Ab, _ = sla.matrix_balance(A, permute=False)   # exact: diagonal powers of 2
    if A.shape[0] > MP_MAX_STATES:
        return sla.eigvals(Ab)
    with mpmath.workdps(dps):
        ev = mpmath.eig(mpmath.matrix(Ab.tolist()), left=False, right=False)
    return np.array([complex(e) for e in ev])


def stability(sys, rtol: float = 1e-9) -> tuple[bool, str]:
    """(stable, description): every pole's real part below ``-rtol |p|`` (or ``0`` for a pole at 0)."""
    p = poles(sys)
    if p.size == 0:
        return True, "no states"
    margin = p.real / np.maximum(np.abs(p), np.finfo(float).tiny)
    k = int(np.argmax(margin))
    worst = p[k]
    ok = bool(np.all(margin < -rtol))
    text = (f"{'stable' if ok else 'NOT stable'}: least stable pole {worst.real:.3g}{worst.imag:+.3g}j "
            f"(|p| {abs(worst):.3g}); poles span {np.abs(p).min():.2g}..{np.abs(p).max():.2g} rad/s")
    return ok, text


def freqresp(sys, omega) -> np.ndarray:
    """Frequency response (len(omega), outputs, inputs) by a dense complex LU solve per frequency."""
    s = ct.ss(sys)
    A, B, C, D = (np.asarray(M, float) for M in (s.A, s.B, s.C, s.D))
    n = A.shape[0]
    out = np.empty((len(omega), C.shape[0], B.shape[1]), complex)
    for i, w in enumerate(np.asarray(omega, float)):
        out[i] = D + (C @ np.linalg.solve(1j * w * np.eye(n) - A, B) if n else 0.0)
    return out


def _ab13md(M, nblock, itype) -> float:
    return float(ab13md(np.asarray(M, complex), np.asarray(nblock, int), np.asarray(itype, int))[0])


def mu_peak(CL, nblock, itype, omega, refine: int = 4, tol: float = 1e-4) -> tuple[float, float]:
    """Peak of AB13MD's upper bound over ``omega`` and its ``refine`` largest local maxima refined.

    ``nblock``/``itype`` follow AB13MD (``itype`` 1 real, 2 complex); the loop's
    inputs/outputs must be ordered as the blocks.  Returns (peak, frequency).
    """
    omega = np.asarray(omega, float)
    H = freqresp(CL, omega)
    vals = np.array([_ab13md(h, nblock, itype) for h in H])
    best = int(np.argmax(vals))
    peak, w_peak = vals[best], omega[best]
    interior = [i for i in range(1, len(vals) - 1) if vals[i] >= vals[i - 1] and vals[i] >= vals[i + 1]]
    for i in sorted(interior, key=lambda i: -vals[i])[:refine]:
        lo, hi = math.log(omega[i - 1]), math.log(omega[i + 1])

        def f(x):
            return _ab13md(freqresp(CL, [math.exp(x)])[0], nblock, itype)
        g = (math.sqrt(5) - 1) / 2
        a, b = lo, hi
        c, d = b - g * (b - a), a + g * (b - a)
        fc, fd = f(c), f(d)
        while b - a > tol:
            if fc > fd:
                b, d, fd = d, c, fc
                c = b - g * (b - a)
                fc = f(c)
            else:
                a, c, fc = c, d, fd
                d = a + g * (b - a)
                fd = f(d)
        for x, v in ((c, fc), (d, fd)):
            if v > peak:
                peak, w_peak = v, math.exp(x)
    return float(peak), float(w_peak)


def hinf_norm(CL) -> float:
    """H-infinity norm by SLICOT AB13DD (through python-control's slycot wrapper)."""
    from slycot import ab13dd
    s = ct.ss(CL)
    n, m, p = s.A.shape[0], s.B.shape[1], s.C.shape[0]
    out = ab13dd("C", "I", "N", "D", n, m, p, np.asarray(s.A, float), np.eye(n), np.asarray(s.B, float),
                 np.asarray(s.C, float), np.asarray(s.D, float))
    return float(out[0])


def mixed_mu_brute_force(M, nreal: int, points: int = 41, polish: int = 1, sizes=None) -> float:
    r"""Mixed mu of ``M`` with ``nreal`` real scalar blocks first (block ``i`` is
    :math:`\delta_i I_{s_i}`, ``sizes`` the :math:`s_i`, all 1 by default) and one full complex
    block last (any shape), from the main loop theorem: :math:`\mu < \beta` iff for every real
    :math:`|\delta_i| \le 1/\beta`, :math:`I - M_{11}\Delta_r` is nonsingular and
    :math:`\bar\sigma(\mathcal F_u(M, \Delta_r)) < \beta`.  The grid of the real parameters
    includes the box's corners and its ``polish`` best points are polished (Powell); the value
    is a lower bound on mu, tight when the polish finds the worst parameters."""
    sizes = np.ones(nreal, int) if sizes is None else np.asarray(sizes, int)
    if sizes.shape != (nreal,) or np.any(sizes < 1):
        raise ValueError(f"sizes must hold {nreal} positive block sizes, got {sizes!r}")
    m = int(sizes.sum())
    M11, M12, M21, M22 = M[:m, :m], M[:m, m:], M[m:, :m], M[m:, m:]
    grid = np.array(list(itertools.product(np.linspace(-1.0, 1.0, points), repeat=nreal)))

    def gains(d):
        d = np.repeat(d, sizes, axis=1)                               # the diagonal of Delta_r
        A = np.eye(m)[None] - M11[None] * d[:, None, :]              # I - M11 diag(d)
        if np.min(np.abs(np.linalg.det(A))) < 1e-12:
            return np.full(d.shape[0], np.inf)
        X = np.linalg.solve(A, np.broadcast_to(M12, (d.shape[0],) + M12.shape))
        return np.linalg.norm(M22[None] + M21[None] @ (d[:, :, None] * X), 2, axis=(1, 2))

    def worst(beta):
        g = gains(grid / beta)
        best = g.max()
        if not np.isfinite(best):
            return best
        # polish the best grid points (the maximum may lie between grid points)
        for k in np.argsort(-g)[:polish]:
            r = minimize(lambda x: -min(gains(np.clip(x, -1, 1)[None] / beta)[0], 1e300), grid[k], method="Powell",
                         bounds=[(-1, 1)] * nreal, options={"xtol": 1e-9, "ftol": 1e-12})
            best = max(best, -r.fun)
        return best

    return fixed_point_level(worst, np.linalg.norm(M, 2))


def fixed_point_level(worst, top: float, rtol: float = 1e-7) -> float:
    """The level where ``worst(beta) = beta`` (``worst`` falls as ``beta`` grows), on ``(0, top]``;
    mu never exceeds the largest singular value ``top``.

    Bisection until both ends of the bracket are finite values of ``worst(beta) - beta`` (near 0
    the box of real parameters is huge and ``I - M11 Delta`` singular), then Brent's method on
    that bracket: the same level to ``rtol`` in about a third of the evaluations.  Returns the
    bracket's lower end, a level where ``worst(beta) >= beta`` held (a lower bound on mu)."""
    lo, hi = 0.0, top * (1 + 1e-9)
    f_lo, f_hi = math.inf, None
    while hi - lo > rtol * hi:
        if lo > 0 and f_hi is not None and np.isfinite(f_lo) and np.isfinite(f_hi):
            break
        mid = 0.5 * (lo + hi)
        f_mid = worst(mid) - mid
        if f_mid >= 0:
            lo, f_lo = mid, f_mid
        else:
            hi, f_hi = mid, f_mid
    else:
        return lo
    state = {"lo": lo}

    def f(beta):
        v = worst(beta) - beta
        if v >= 0 and beta > state["lo"]:
            state["lo"] = beta
        return v

    brentq(f, lo, hi, xtol=rtol * hi, rtol=4 * np.finfo(float).eps)
    return state["lo"]
