r"""The search for a controller that passes the check: central and LMI constructions over the
back-off schedule, regularised plants, and the plants whose optimal level is zero.
"""
from __future__ import annotations

import time
from dataclasses import replace

import cvxpy as cp
import numpy as np
import scipy.linalg as sla

from ..errors import IllPosedError, InfeasibleError, ModelError, SolverError
from ..lti import ss
from ._central import _add_d22, central_controller
from ._level import _Level, _scale, _working_plant, CENTRAL, CENTRAL_REGULARISED, LMI_CONTROLLER
from ._lmi import _controller_at
from ._plant import _sym, PlantParts
from ._riccati import _regularised, _riccati_level
from ._verify import _verify, HinfResult


_EPS_REGULARISE = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)


def _regularised_search(P, nmeas, ncon, parts: PlantParts, scale: bool, tries: list,
                        eps_list=_EPS_REGULARISE):
    """Singular problems: central controllers of regularised plants (:func:`_regularised`).

    For each ``eps`` the level of the regularised plant is found by the Riccati
    gamma iteration and its central controller built 1e-4 above it; each one is
    verified on the closed loop with the original ``P``.  The regularised level
    is an upper bound of the singular one that falls towards it as ``eps``
    decreases, until the Riccati solutions lose accuracy; the verified
    controller with the lowest closed-loop norm is returned (a candidate dict
    of :func:`_search`, or None).  On the two-mass plant with ``D21 = 0`` this
    gives 0.8070 where the LMI level reads 0.8187 and its controller achieves 0.8175;
    on the model-based identification plants of the cracked rotor it is the only
    construction that reaches 1e-4 of the level on all of them."""
    base = _working_plant(parts, scale)
    best = None
    for eps in eps_list:
        pe = _regularised(base.work, float(eps))
        try:
            r = _riccati_level(pe)
        except (IllPosedError, np.linalg.LinAlgError, ValueError):
            r = None
        if r is None:
            tries.append({"construction": CENTRAL_REGULARISED, "eps": float(eps), "backoff": 1e-4,
                          "gamma_target": float("nan"), "error": "no level found by the Riccati gamma iteration"})
            continue
        lev = replace(base, work=pe, gamma=r[0] * base.gscale)
        n0 = len(tries)
        cand, _ = _search(P, nmeas, ncon, lev, [1e-4], tries, "", "coupling", 1.0, central=True, lmi=False)
        for t in tries[n0:]:
            t.update(construction=CENTRAL_REGULARISED, eps=float(eps))
        if cand is not None and cand["stable"]:
            cand["construction"] = f"{CENTRAL_REGULARISED} (eps = {eps:.0e})"
            if best is None or cand["value"] < best["value"]:
                best = cand
    return best


def _passes(c, level: float | None = None) -> bool:
    """A stable loop within its target; with ``level`` (a Riccati level) also not more
    than 0.1 % below it: a controller doing much better than the level proves that the
    gamma iteration went wrong (feasibility that is not monotone in gamma numerically,
    seen on plants with D21 ~ 1e-10), and the LMIs must take over."""
    ok = c is not None and c["stable"] and c["value"] <= c["gamma_target"] * (1 + 1e-6)
    if ok and level is not None:
        ok = c["value"] >= level * (1 - 1e-3)
    return ok


def _search(P, nmeas, ncon, lev: _Level, schedule, tries: list, solver, controller_objective, bound_factor,
            central: bool, lmi: bool, first=None):
    """Controllers at the back-off levels of ``schedule`` above ``lev.gamma``, each
    verified on the closed loop rebuilt from ``P`` (:func:`_verify`); stops at the
    first one that achieves its target and returns ``(candidate, passed)``: the
    stable candidate with the lowest closed-loop norm so far (a dict), and
    whether any candidate achieved its target.

    At each level the central controller comes first (where the Riccati
    solutions exist there), then the LMI reconstruction: the preferred objective,
    the other one, and ``X, Y`` bounded more tightly (solvers sometimes fail on
    one formulation and solve another cleanly)."""
    work0, gscale = lev.work, lev.gscale
    variants = []
    if lmi and lev.R is not None:
        bound = bound_factor * max(np.linalg.eigvalsh(_sym(lev.R)).max(), np.linalg.eigvalsh(_sym(lev.S)).max(),
                                   1.0)
        objectives = [controller_objective] + [o for o in ("coupling", "margin") if o != controller_objective]
        variants = [(o, bound) for o in objectives] + [("margin", bound * 1e-2)]
    best = first
    if first is not None and first["stable"] and first["value"] <= lev.gamma * (1 + schedule[0]) * (1 + 1e-6) \
            and lev.status != "riccati":
        return first, True     # a controller found before (regularised plant) already achieves the level
    for b in schedule:
        gK = lev.gamma * (1.0 + b)
        builders = []
        if central:
            builders.append((CENTRAL, None, None))
        builders += [(LMI_CONTROLLER, o, bnd) for o, bnd in variants]
        for construction, objective, bnd in builders:
            rec = {"construction": construction, "backoff": b, "gamma_target": gK}
            if objective is not None:
                rec.update(objective=objective, bound=bnd)
            try:
                if objective is None:
                    Ak, Bk, Ck, Dk, info = central_controller(work0, gK / gscale)
                else:
                    Ak, Bk, Ck, Dk, info = _controller_at(work0, gK / gscale, solver, bnd, objective=objective,
                                                         gscale=gscale)
                Ak, Bk, Ck, Dk = _add_d22(Ak, Bk, Ck, Dk, lev.D22)
            except (InfeasibleError, SolverError, IllPosedError, np.linalg.LinAlgError) as exc:
                tries.append({**rec, "error": str(exc)})
                continue
            if not all(np.all(np.isfinite(X)) for X in (Ak, Bk, Ck, Dk)):
                tries.append({**rec, "error": "controller construction gave non-finite matrices"})
                continue
            # undo the time scaling K(s) = K_w(s / alpha), then u = su * K_s(sy * y)
            ra = np.sqrt(lev.alpha)
            Ak, Bk, Ck = lev.alpha * Ak, ra * Bk, ra * Ck
            K = ss(Ak, Bk * lev.sy[None, :], lev.su[:, None] * Ck, lev.su[:, None] * Dk * lev.sy[None, :],
                   inputs=P.output_labels[-nmeas:], outputs=P.input_labels[-ncon:], name="K")
            CL, stable, maxre, value, wpk, sly, gpk, stab = _verify(P, K, nmeas, ncon)
            tries.append({**rec, "stable": stable, "closed_loop_norm": value, "stability": stab.message, **info})
            cand = {"K": K, "CL": CL, "stable": stable, "maxre": maxre, "value": value, "wpk": wpk, "sly": sly,
                    "gpk": gpk, "gamma_target": gK, "backoff": b, "construction": construction,
                    "stability": stab.message}
            if best is None or (stable and (not best["stable"] or value < best["value"])):
                best = cand
            if lev.status == "riccati" and stable and value < lev.gamma * (1 - 1e-3):
                return best, False    # the Riccati level is wrong (see _passes): no use going on
            if _passes(cand, lev.gamma if lev.status == "riccati" else None):
                # the lowest achieved norm so far: a near miss at a smaller back-off
                # (1e-5 above its target) beats a pass at the next one
                return best, True
    return best, False


#: a Riccati level this far below the plant's w -> z scale is 0 to double precision
_ZERO_LEVEL = 1e-12


def _zero_infimum(P, nmeas, ncon, lev: _Level, tries, solver, controller_objective, bound_factor, notes, best):
    r"""The Riccati conditions hold at every level (e.g. square ``D12``, ``D21`` with
    :math:`A - B_2 D_{12}^{-1} C_1` and :math:`A - B_1 D_{21}^{-1} C_2` stable:
    :math:`X_\infty = Y_\infty = 0`): the infimum is 0 and is not attained, the
    central controllers grow without bound as the level goes to 0.  Controllers are
    built at levels 1e-1, 1e-2, ... of the plant's w -> z scale until one fails its
    check; the lowest verified one is returned with its level."""
    found = None
    for k in range(1, 13):
        trial = replace(lev, gamma=lev.gscale * 10.0 ** -k, status="zero infimum")
        cand, ok = _search(P, nmeas, ncon, trial, [1e-4], tries, solver, controller_objective, bound_factor,
                           central=True, lmi=False)
        if not ok:
            break
        found = (cand, trial)
    if found is None:
        return best, False, lev
    notes.append(f"the Riccati conditions hold at every level: the optimal level is 0 and is not attained "
                 f"(controllers grow without bound as the level goes to 0); the controller returned is the "
                 f"lowest of the levels 1e-1, 1e-2, ... times {lev.gscale:.3g} that passed its check")
    return found[0], True, replace(found[1], method=lev.method + "; infimum 0, not attained")


_BACKOFFS = (1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3)


def _check_options(solver, backoff, max_backoff, controller_objective, bound_factor, method="auto"):
    """Named errors for bad keyword arguments of :func:`hinfsyn` (before any solver runs)."""
    if not isinstance(solver, str) or not solver:
        raise ModelError(f"solver must be a cvxpy solver name (a string), got {solver!r}")
    if solver.upper() not in cp.installed_solvers():
        raise ModelError(f"solver {solver!r} is not installed; installed: {', '.join(cp.installed_solvers())}")
    for name, v in (("backoff", backoff), ("max_backoff", max_backoff), ("bound_factor", bound_factor)):
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, float, np.integer, np.floating)) \
                or not np.isfinite(v) or v <= 0:
            raise ModelError(f"{name} must be a positive finite number, got {v!r}")
    if backoff > 1.0 or max_backoff > 1.0:
        raise ModelError(f"backoff and max_backoff are relative distances above the optimal level and must "
                         f"be at most 1 (100 %), got backoff={backoff!r}, max_backoff={max_backoff!r}")
    if controller_objective not in ("coupling", "margin"):
        raise ModelError(f"controller_objective must be 'coupling' or 'margin', got {controller_objective!r}")
    if method not in ("auto", "riccati", "lmi"):
        raise ModelError(f"method must be 'auto', 'riccati' or 'lmi', got {method!r}")


def _zero_level(P, parts, nmeas, ncon, notes, solver, scale, t0):
    """The exogenous input w reaches no state and no z (B1 = 0, D11 = 0), or z
    sees no state (C1 = 0, D11 = 0): every stabilizing controller gives the
    closed-loop norm 0, the optimal level.  The LMIs degenerate at level 0, so
    an observer-based stabilizing controller (two Riccati equations) is built
    instead and checked like the LMI controllers."""
    if scale:
        work, su, sy, _, alpha, _ = _scale(parts)
    else:
        work, su, sy, alpha = parts, np.ones(ncon), np.ones(nmeas), 1.0
    A, B2, C2 = work.A, work.B2, work.C2
    n = A.shape[0]
    try:
        X = sla.solve_continuous_are(A, B2, np.eye(n), np.eye(ncon))
        Y = sla.solve_continuous_are(A.T, C2.T, np.eye(n), np.eye(nmeas))
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise SolverError(f"H-infinity synthesis at the optimal level 0 (w reaches no z): the Riccati "
                          f"equations of the stabilizing observer-based controller failed ({exc})") from None
    F = B2.T @ X
    L = Y @ C2.T
    Ak, Bk, Ck, Dk = A - B2 @ F - L @ C2, L, -F, np.zeros((ncon, nmeas))
    Ak, Bk, Ck, Dk = _add_d22(Ak, Bk, Ck, Dk, work.D22)
    ra = np.sqrt(alpha)
    Ak, Bk, Ck = alpha * Ak, ra * Bk, ra * Ck
    K = ss(Ak, Bk * sy[None, :], su[:, None] * Ck, su[:, None] * Dk * sy[None, :],
           inputs=P.output_labels[-nmeas:], outputs=P.input_labels[-ncon:], name="K")
    CL, stable, maxre, value, wpk, sly, gpk, stab = _verify(P, K, nmeas, ncon)
    if not stable:
        raise SolverError("H-infinity synthesis at the optimal level 0 (w reaches no z): the observer-based "
                          f"controller does not stabilize the closed loop ({stab.message})")
    notes = list(notes) + ["the exogenous input w reaches no performance output z for any controller "
                           "(B1 = 0 and D21 = 0, or C1 = 0 and D12 = 0; D11 = 0): the optimal level is 0 and any stabilizing "
                           "controller attains it; an observer-based (LQG-type) controller is returned"]
    poles = np.linalg.eigvals(np.asarray(K.A, float)) if K.nstates else np.zeros(0)
    return HinfResult(K=K, CL=CL, gamma=0.0, gamma_target=0.0, closed_loop_norm=value,
                      closed_loop_norm_slycot=sly, closed_loop_norm_grid=gpk, peak_frequency=wpk,
                      stable=stable, max_closed_loop_real_part=maxre, controller_poles=poles,
                      backoff=0.0, notes=notes, solver=solver, seconds=time.perf_counter() - t0,
                      info={"tries": [], "level_method": "exact (w does not reach z)", "u_scaling": su,
                            "y_scaling": sy})
