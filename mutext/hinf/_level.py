r"""The optimal level and the working coordinates it is computed in (states balanced, time
rescaled, ``u`` and ``y`` normalised): the Riccati gamma iteration where the problem is
regular, the LMIs otherwise.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import cvxpy as cp
import numpy as np

from ..errors import IllPosedError, InfeasibleError, SolverError
from ..lti import balance_states, ss
from ._lmi import _balancing_transform, _optimal_level, _transform
from ._plant import PlantParts
from ._riccati import _near_axis_hint, _refine_level, _riccati_level


@dataclass
class _Level:
    """Optimal level and the working coordinates it was computed in."""
    work: PlantParts       # scaled plant with D22 = 0 (level = gamma / gscale)
    D22: np.ndarray        # D22 of the scaled plant
    gscale: float
    gamma: float           # true optimal level
    gamma_lmi: float
    R: np.ndarray
    S: np.ndarray
    status: str
    levels: list
    method: str
    su: np.ndarray
    sy: np.ndarray
    tstate: np.ndarray
    alpha: float = 1.0  # time scaling, P_work(s) = P(alpha s)


def _time_scale(p: PlantParts, alpha: float) -> PlantParts:
    """The plant with frequency axis rescaled, P'(s) = P(alpha s); the H-infinity
    level is unchanged and a controller K' for P' gives K(s) = K'(s / alpha)."""
    r = 1.0 / np.sqrt(alpha)
    return PlantParts(p.A / alpha, r * p.B1, r * p.B2, r * p.C1, r * p.C2, p.D11, p.D12, p.D21, p.D22)


def _scale(parts: PlantParts):
    """Balance states, rescale time, normalise the w -> z gain and the u and y channels.

    Returns ``(scaled parts, su, sy, t, alpha, c0)`` with ``u = diag(su) u_s``,
    ``y_s = diag(sy) y``, the frequency axis rescaled by ``alpha`` (see
    :func:`_time_scale`) and w, z scaled so that the level of the scaled plant
    is the level of the original divided by ``c0``.  Every factor is a power of
    two and the steps are ordered so that multiplying the plant's matrices by
    constants (units, time scale) gives the same scaled plant: the answer is
    scale-invariant (multiplying every matrix by 1e8 used to move the level).
    """
    p = parts
    n, nw, nu, nz, ny = p.sizes
    B = np.hstack([p.B1, p.B2])
    C = np.vstack([p.C1, p.C2])
    D = np.block([[p.D11, p.D12], [p.D21, p.D22]])
    bal, t = balance_states(ss(p.A, B, C, D)) if n else (ss(p.A, B, C, D), np.ones(0))
    A, B, C = (np.asarray(X, float) for X in (bal.A, bal.B, bal.C))
    work = PlantParts(A, B[:, :nw], B[:, nw:], C[:nz], C[nz:], p.D11, p.D12, p.D21, p.D22)
    # frequencies of order one: the LMI entries A R + R A^T and the gamma blocks
    # are then of comparable size
    alpha = 1.0
    mags = np.abs(np.linalg.eigvals(A)) if n else np.zeros(0)
    if mags.size and mags.max() > 0:
        alpha = float(2.0 ** np.round(np.log2(mags.max())))
        work = _time_scale(work, alpha)
    # w -> z gain of order one (a rough, coordinate-free estimate); done before
    # the u, y normalisation so that the latter does not depend on the units of z, w
    g_est = max(float(np.linalg.norm(work.D11, 2)) if work.D11.size else 0.0,
                (float(np.linalg.norm(work.C1, 2)) * float(np.linalg.norm(work.B1, 2))) if n else 0.0)
    c0 = float(2.0 ** np.round(np.log2(g_est))) if g_est > 0 and np.isfinite(g_est) else 1.0
    if c0 != 1.0:
        work = _transform(work, np.eye(n), c0)
    cu = np.linalg.norm(np.vstack([work.B2, work.D12]), axis=0)
    su = np.where(cu > 0, 2.0 ** -np.round(np.log2(np.where(cu > 0, cu, 1.0))), 1.0)
    ry = np.linalg.norm(np.hstack([work.C2, work.D21]), axis=1)
    sy = np.where(ry > 0, 2.0 ** -np.round(np.log2(np.where(ry > 0, ry, 1.0))), 1.0)
    w = work
    scaled = PlantParts(w.A, w.B1, w.B2 * su, w.C1, w.C2 * sy[:, None], w.D11, w.D12 * su,
                        w.D21 * sy[:, None], (w.D22 * su) * sy[:, None])
    return scaled, su, sy, t, alpha, c0


def _level(parts: PlantParts, notes: list, solver: str, scale: bool, refine: bool) -> _Level:
    nmeas, ncon = parts.C2.shape[0], parts.B2.shape[1]
    if scale:
        work, su, sy, tstate, alpha, c0 = _scale(parts)
    else:
        work, su, sy, tstate, alpha, c0 = parts, np.ones(ncon), np.ones(nmeas), np.ones(parts.n), 1.0, 1.0
    D22 = work.D22
    work0 = PlantParts(work.A, work.B1, work.B2, work.C1, work.C2, work.D11, work.D12, work.D21,
                       np.zeros_like(D22))
    # Pass 0 locates the level.  If the solver gives up, retry with w and z
    # scaled down (large levels make the gamma blocks dominate the LMIs).
    gscale, first, errors = c0, None, []
    for c in (1.0, 1e3, 1e6):
        trial = _transform(work0, np.eye(parts.n), c) if c != 1.0 else work0
        for tight in (False, True):
            try:
                first = _optimal_level(trial, solver, tight=tight)
                break
            except SolverError as exc:
                errors.append(str(exc))
            except InfeasibleError as exc:
                errors.append(str(exc))
                break
            except (ValueError, np.linalg.LinAlgError) as exc:   # NaN in the problem data
                errors.append(f"H-infinity optimal level: {exc}")
                break
        if first is not None:
            work0, gscale = trial, c0 * c
            break
    if first is None:
        raise SolverError(f"H-infinity optimal level: the LMI solver failed on the scaled plant{_near_axis_hint(parts)} "
                          f"(tried w, z scalings 1, 1e3, 1e6); last error: {errors[-1]}")
    g0, R, S, st1 = first
    if not np.isfinite(g0) or g0 < 1e-8:
        # the level of the normalised plant (w -> z gain of order one) is zero to
        # the solver's accuracy: a singular problem whose infimum 0 is approached
        # only by controllers of unbounded gain (e.g. an integrator with full
        # control and measurement, z = x); there is no controller to return
        raise IllPosedError(
            f"H-infinity optimal level: the infimum of the closed-loop norm is 0 to solver accuracy "
            f"(level {g0 * gscale:.3g} against a w -> z gain of about {gscale:.3g}); it is approached only by "
            "controllers of unbounded gain and not attained (a singular problem: D12 or D21 rank deficient "
            "without a penalty on u or noise on y). Add a control penalty in z or sensor noise in y.")
    # Later passes re-solve in the state coordinates that balance the previous
    # solution (R, S) and with w, z scaled so that the level is near 1.
    # Plant-based balancing alone leaves R and S spread over decades, which
    # costs the solver digits.  A pass that raises the level is discarded.
    gamma = g0 * gscale
    levels = [gamma]
    best = (gamma, work0, gscale, R, S, st1)
    for _ in range(3):
        T = _balancing_transform(R, S)
        if T is None or not np.all(np.isfinite(T)):
            T = np.eye(parts.n)
        c = gamma / gscale
        trial = _transform(work0, T, c)
        if not all(np.all(np.isfinite(X)) for X in (trial.A, trial.B1, trial.B2, trial.C1, trial.C2, trial.D11,
                                                      trial.D12, trial.D21)):
            break
        try:
            g2, R2, S2, st2 = _optimal_level(trial, solver, tight=True)
        except (InfeasibleError, SolverError, ValueError, np.linalg.LinAlgError):
            break
        g2 *= gscale * c
        levels.append(g2)
        if st2 != cp.OPTIMAL:
            break
        work0, R, S, st1, gscale = trial, R2, S2, st2, gscale * c
        converged = abs(g2 - gamma) <= 1e-9 * gamma
        if g2 > best[0] * (1 + 1e-7):
            break
        gamma = g2
        best = (gamma, work0, gscale, R, S, st1)
        if converged:
            break
    gamma, work0, gscale, R, S, st1 = best
    if not np.isfinite(gamma) or gamma <= 0:
        raise SolverError(f"H-infinity optimal level: solver returned gamma={gamma}")
    gamma_lmi = gamma
    level_method = "LMI"
    if st1 != cp.OPTIMAL:
        level_method = f"LMI (solver status {st1})"
    regular = not any(n.startswith(("D12 does not", "D21 does not", "[A - jwI")) for n in notes)
    if regular and refine:
        g_ref = _refine_level(work0, gamma / gscale)
        if g_ref is not None and g_ref * gscale <= gamma * (1 + 1e-3):
            gamma = g_ref * gscale
            level_method += ", refined by bisection on the Riccati conditions"
            if gamma < gamma_lmi * (1 - 1e-4):
                notes.append(f"the LMI solver's level {gamma_lmi:.6g} was inaccurate; the Riccati "
                             f"conditions (ZDG Thm 17.1) place the optimum at {gamma:.6g}")
    return _Level(work0, D22, gscale, gamma, gamma_lmi, R, S, st1, levels, level_method, su, sy,
                  tstate, alpha)


CENTRAL = "central (Glover-Doyle formulas from the Riccati solutions)"


LMI_CONTROLLER = "LMI (Scherer-Gahinet-Chilali reconstruction)"


CENTRAL_REGULARISED = "central of the regularised plant (Glover-Doyle formulas, eps * u added to z, eps * v to y)"


def _working_plant(parts: PlantParts, scale: bool) -> _Level:
    """The scaled plant with ``D22`` set aside (a :class:`_Level` without a level yet)."""
    nmeas, ncon = parts.C2.shape[0], parts.B2.shape[1]
    if scale:
        work, su, sy, tstate, alpha, c0 = _scale(parts)
    else:
        work, su, sy, tstate, alpha, c0 = parts, np.ones(ncon), np.ones(nmeas), np.ones(parts.n), 1.0, 1.0
    work0 = PlantParts(work.A, work.B1, work.B2, work.C1, work.C2, work.D11, work.D12, work.D21,
                       np.zeros_like(work.D22))
    return _Level(work0, work.D22, c0, float("nan"), float("nan"), None, None, "", [], "", su, sy, tstate, alpha)


def _well_conditioned_d(parts: PlantParts, scale: bool, tol: float = 1e-8) -> bool:
    """``D12`` and ``D21`` of the working plant (``u`` and ``y`` channels normalised)
    have smallest singular values above ``tol``."""
    w = _working_plant(parts, scale).work
    s12 = np.linalg.svd(w.D12, compute_uv=False)
    s21 = np.linalg.svd(w.D21, compute_uv=False)
    return bool(s12.size and s21.size and s12[-1] > tol and s21[-1] > tol)


def _level_riccati(parts: PlantParts, scale: bool) -> _Level | None:
    """The optimal level by the Riccati gamma iteration (:func:`_riccati_level`)
    on the scaled plant, or None if it finds no feasible level."""
    lev = _working_plant(parts, scale)
    try:
        r = _riccati_level(lev.work)
    except (IllPosedError, np.linalg.LinAlgError, ValueError):
        return None
    if r is None:
        return None
    g, steps = r
    return replace(lev, gamma=g * lev.gscale, status="riccati", levels=[g * lev.gscale],
                   method=f"Riccati gamma iteration ({steps} steps of bisection on ZDG Thm 17.1)")
