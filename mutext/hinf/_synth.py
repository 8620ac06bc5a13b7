r"""H-infinity synthesis: the level and the controller by the routes of the ``method`` setting."""
from __future__ import annotations

import time

import numpy as np

from ..errors import IllPosedError, ModelError, SolverError
from ._level import _level, _level_riccati, _well_conditioned_d
from ._plant import check_plant
from ._riccati import _near_axis_hint
from ._search import _BACKOFFS, _check_options, _regularised_search, _search, _zero_infimum, _ZERO_LEVEL, _zero_level
from ._verify import HinfResult


def hinfsyn(P, nmeas: int, ncon: int, *, solver: str = "CLARABEL", backoff: float = 1e-4,
            scale: bool = True, max_backoff: float = 0.3, refine: bool = True,
            controller_objective: str = "coupling", bound_factor: float = 1e3,
            method: str = "auto") -> HinfResult:
    r"""H-infinity synthesis (same argument order as :func:`control.hinfsyn`).

    The optimal level comes from the Riccati gamma iteration where the problem
    is regular and the iteration succeeds, from the LMIs otherwise; the
    controller is the central one (:func:`central_controller`) where the
    Riccati solutions exist at the target level, the LMI reconstruction
    otherwise.  Every controller is checked on the closed loop rebuilt from
    ``P`` (stability by the scale-aware rule of :func:`mutext.lti.stability`,
    norm recomputed); the first that achieves its target level is returned.
    ``info["level_method"]`` and ``construction`` say which routes were used.

    Parameters
    ----------
    P : control.StateSpace
        Generalized plant with inputs ``[w; u]`` and outputs ``[z; y]``
        (continuous time).
    nmeas : int
        Number of measurements ``y`` (the last outputs of ``P``).
    ncon : int
        Number of control inputs ``u`` (the last inputs of ``P``).
    solver : str
        cvxpy solver name (default Clarabel).
    backoff : float
        The controller is built at level ``gamma * (1 + backoff)``; a strictly
        suboptimal level keeps it well conditioned.  If the closed loop fails
        the check (unstable, or norm above the target level), the backoff is
        raised step by step (1e-4, 3e-4, 1e-3, ...) up to ``max_backoff``.
        Central controllers achieve their target to about 1e-8 relative on
        badly scaled random plants, so the first step normally suffices.
    max_backoff : float
        Largest relative backoff tried (at most 1; default 0.3, i.e. a
        controller up to 30 % above the optimal level before the synthesis
        gives up).
    scale : bool
        Balance the plant's states, rescale time and normalise ``u``, ``y``
        first (recommended).
    refine : bool
        On the LMI route, for regular problems, refine the LMI level by
        bisection on the exact Riccati existence conditions
        (:func:`riccati_feasible`).
    controller_objective : {"coupling", "margin"}
        How a point inside the controller LMI is chosen: "coupling" keeps
        ``I - XY`` far from singular (fewer needlessly fast controller poles);
        "margin" maximises a uniform margin of both LMIs.  The other one is
        tried if the first yields no stabilizing controller.
    bound_factor : float
        ``X`` and ``Y`` of the controller LMI are bounded by this factor times
        the largest eigenvalue of the level LMI solution.
    method : {"auto", "riccati", "lmi"}
        "auto": for regular problems (``D12`` full column rank, ``D21`` full
        row rank) the level by bisection on the Riccati conditions
        (:func:`riccati_feasible`) and the central controller; the LMIs
        (level and controller) where that fails or the problem is singular.
        "riccati": that route only (an error where it fails).  "lmi": the
        textbook LMI route only (level and controller from LMIs).

    Returns
    -------
    HinfResult
        Controller ``K``, closed loop ``CL``, optimal level ``gamma``, the
        independently recomputed closed-loop norm and the construction used.

    Raises
    ------
    ModelError
        Wrong port counts, non-finite entries, discrete-time plant.
    IllPosedError
        ``(A, B2)`` not stabilizable or ``(C2, A)`` not detectable.
    InfeasibleError, SolverError
        The LMIs could not be solved, or no controller passing the check was
        found (the message names the deciding closed-loop pole).

    Examples
    --------
    >>> from mutext.examples import two_mass
    >>> res = hinfsyn(two_mass.plant(), 1, 1)
    >>> round(res.gamma, 4)
    1.0069
    """
    t0 = time.perf_counter()
    _check_options(solver, backoff, max_backoff, controller_objective, bound_factor, method)
    P, parts, notes = check_plant(P, nmeas, ncon)
    if parts.n == 0:
        raise ModelError("P has no states: static H-infinity synthesis is not supported")
    # w reaches no z for any controller only when it enters nothing (B1 = 0, D21 = 0) or z reads
    # nothing (C1 = 0, D12 = 0); with B1 = 0 alone w still enters through the measurement (D21)
    if not np.any(parts.D11) and ((not np.any(parts.B1) and not np.any(parts.D21))
                                  or (not np.any(parts.C1) and not np.any(parts.D12))):
        return _zero_level(P, parts, nmeas, ncon, notes, solver, scale, t0)
    regular, well_posed = _route_conditions(parts, notes, method, scale)
    lev = _first_level(P, parts, notes, method, solver, scale, refine, well_posed)
    schedule = [x for x in _BACKOFFS if backoff <= x <= max_backoff] or [backoff]
    tries = []
    best = None
    if not well_posed and method == "auto":
        best = _regularised_search(P, nmeas, ncon, parts, scale, tries)
    best, passed = _search(P, nmeas, ncon, lev, schedule, tries, solver, controller_objective, bound_factor,
                           central=regular and method != "lmi", lmi=method != "riccati", first=best)
    if not passed and lev.status == "riccati" and lev.gamma <= _ZERO_LEVEL * lev.gscale:
        best, passed, lev = _zero_infimum(P, nmeas, ncon, lev, tries, solver, controller_objective,
                                          bound_factor, notes, best)
    if not passed and method == "auto" and lev.R is None:
        best, lev = _lmi_takes_over(P, nmeas, ncon, parts, notes, lev, schedule, tries, best, solver, scale,
                                    refine, controller_objective, bound_factor, regular)
    if best is None or not best["stable"]:
        _no_controller(P, lev.gamma, tries, schedule)
    return _result(best, lev, notes, tries, solver, t0)


def _route_conditions(parts, notes, method, scale):
    """Whether the problem is regular (``D12``, ``D21`` of full rank, no rank loss on the axis)
    and well posed for the Riccati route (not nearly singular either); ``method="riccati"``
    on a problem that is not regular is an error.  Adds the notes on ``D22`` and on nearly
    singular ``D12``, ``D21``."""
    regular = not any(n.startswith(("D12 does not", "D21 does not", "[A - jwI")) for n in notes)
    if method == "riccati" and not regular:
        raise IllPosedError("method='riccati' needs D12 of full column rank, D21 of full row rank and no "
                            "rank loss of the plant's pencils on the imaginary axis; "
                            + "; ".join(n.split(":")[0] for n in notes if n.startswith(("D12", "D21", "[A - jwI")))
                            + " (use method='auto' or 'lmi')")
    if np.any(parts.D22):
        notes.append("D22 is nonzero: controller designed for D22 = 0 and corrected by K = K0 (I + D22 K0)^-1")
    # nearly singular D12 / D21 (smallest singular value below 1e-8 of the channel's gain in the
    # working coordinates) make the normalisation of the Riccati route meaningless: treated like
    # singular ones.  Milder cases are caught by the checks of the central controllers: the
    # model-based identification plants (D21 ~ 1e-10, about 1e-6 in working coordinates) gave
    # Riccati levels 80 times too high, which their own controllers expose (see _passes)
    well_posed = regular and _well_conditioned_d(parts, scale)
    if method == "riccati" and regular and not well_posed:
        notes.append("D12 or D21 is nearly singular (below 1e-8 of its channel): the Riccati route may be inaccurate")
    return regular, well_posed


def _first_level(P, parts, notes, method, solver, scale, refine, well_posed):
    """The optimal level by the Riccati gamma iteration where the route allows it, the LMIs
    otherwise (``method="riccati"``: an error if the iteration finds no level)."""
    lev = _level_riccati(parts, scale) if ((well_posed and method == "auto") or method == "riccati") else None
    if lev is None:
        if method == "riccati":
            raise SolverError("H-infinity synthesis (method='riccati'): the gamma iteration found no level at "
                              f"which the Riccati conditions hold{_near_axis_hint(P)}")
        lev = _level(parts, notes, solver, scale, refine)
    return lev


def _lmi_takes_over(P, nmeas, ncon, parts, notes, lev, schedule, tries, best, solver, scale, refine,
                    controller_objective, bound_factor, regular):
    """The Riccati route gave a level but no central controller passed the check: the LMIs take
    over (level and controller), central controllers at the LMI's level are tried once more,
    and regularised central controllers too.  Returns the best try and the level."""
    notes.append(f"no central controller passed the check at the Riccati level {lev.gamma:.6g} (or one "
                 "did far better than it, so the gamma iteration was wrong); the LMI route and "
                 "regularised central controllers were used")
    lev = _level(parts, notes, solver, scale, refine)
    reg = _regularised_search(P, nmeas, ncon, parts, scale, tries)
    if reg is not None and (best is None or not best["stable"] or reg["value"] < best["value"]):
        best = reg
    best, _ = _search(P, nmeas, ncon, lev, schedule, tries, solver, controller_objective,
                      bound_factor, central=regular, lmi=True, first=best)
    return best, lev


def _no_controller(P, gamma, tries, schedule):
    """Raise the error for a search in which no stabilizing controller passed the check, with the
    last outcome of each construction."""
    last = {}
    for t in tries:
        last[t["construction"] + (f" ({t['objective']})" if "objective" in t else "")] = \
            t.get("error") or f"closed loop at backoff {t['backoff']:g}: {t['stability']}"
    raise SolverError("H-infinity synthesis: no stabilizing controller passed the check "
                      f"(optimal level gamma={gamma:.6g}; {len(tries)} attempts at backoffs "
                      f"{schedule[0]:g}..{schedule[-1]:g}){_near_axis_hint(P)}; last outcome per construction: "
                      + "; ".join(f"{k}: {v}" for k, v in last.items()))


def _result(best, lev, notes, tries, solver, t0) -> HinfResult:
    """The result for the best controller, with the level it proves and notes where the
    controller and the computed level disagree."""
    gamma = lev.gamma
    K, CL, stable, maxre, value, wpk, sly, gpk, gK, b = (best[k] for k in (
        "K", "CL", "stable", "maxre", "value", "wpk", "sly", "gpk", "gamma_target", "backoff"))
    if gamma < lev.gamma_lmi * (1 - 1e-6) and value > lev.gamma_lmi * (1 + 1e-3):
        # check of the reported level against the achieved one: the Riccati
        # refinement lowered the level, but no controller comes near even the LMI's
        notes.append(f"the reported level {gamma:.6g} (Riccati refinement of the LMI level "
                     f"{lev.gamma_lmi:.6g}) is not confirmed by a controller: the best one achieves "
                     f"{value:.6g}; treat the level as uncertain between the two")
    if value > gK * (1 + 1e-6):
        notes.append(f"the best controller found achieves {value:.6g}, above the target level {gK:.6g}")
    elif b > 1e-3:
        notes.append(f"no controller passed the check closer to the optimum: the controller "
                     f"achieves {value:.6g}, {100 * (value / gamma - 1):.2g} % above the optimal level")
    if value < gamma * (1 - 1e-6) and lev.status == "zero infimum":
        gamma = value       # the level is 0; report what the returned controller proves
    elif value < gamma * (1 - 1e-6):
        # a verified controller proves a lower level than the level computation returned
        notes.append(f"the controller achieves {value:.6g}, below the computed level {gamma:.6g}: the level "
                     "was computed inaccurately (on singular problems the infimum is approached only "
                     "by high-gain controllers); gamma is set to the level this controller proves")
        gamma = value
    poles = np.linalg.eigvals(np.asarray(K.A, float)) if K.nstates else np.zeros(0)
    return HinfResult(K=K, CL=CL, gamma=gamma, gamma_target=gK, closed_loop_norm=value,
                      closed_loop_norm_slycot=sly, closed_loop_norm_grid=gpk, peak_frequency=wpk,
                      stable=stable, max_closed_loop_real_part=maxre, controller_poles=poles,
                      backoff=b, notes=notes, solver=solver, seconds=time.perf_counter() - t0,
                      info={"tries": tries, "level_status": lev.status, "levels": lev.levels,
                            "gamma_lmi": lev.gamma_lmi, "level_method": lev.method,
                            "state_scaling": lev.tstate, "u_scaling": lev.su, "y_scaling": lev.sy,
                            "stability": best["stability"]},
                      construction=best["construction"])
