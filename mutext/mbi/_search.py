r"""The search for :math:`W_z`: the grid and the first value, one D-K run per try, the log-log
secant step toward :math:`\mu = 1`, and what the search did."""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import IllPosedError, InfeasibleError, ModelError, SolverError
from ..lti import freqresp
from ._floor import WzFloor
from ._plant import MBIPlant, _default_omega


@dataclass
class WzTry:
    """One D-K run of the W_z search.

    Attributes
    ----------
    Wz : float
        The error bound tried (output unit).
    mu_upper : float
        Upper bound of mu of the run's final controller (the branch-and-bound bound where that was run).
    mu_lower : float
        Lower bound of mu of the run's final controller.
    controller_order : int
        Number of states of the controller.
    seconds : float
        Wall time of the run.
    iterations : int
        Number of D-K iterations.
    mu_dg : float
        The D-G upper bound (before branch and bound).
    """
    Wz: float
    mu_upper: float
    mu_lower: float
    controller_order: int
    seconds: float
    iterations: int
    #: the D-G bound (``mu_upper`` is the branch-and-bound bound where that was run)
    mu_dg: float = float("nan")


@dataclass
class _WzSearch:
    """What the W_z search did: the tries, their (plant, D-K result), the failed K steps, why it stopped."""
    tries: list = field(default_factory=list)
    runs: list = field(default_factory=list)
    failed: list = field(default_factory=list)
    stopped_by_time: bool = False


def _search_grid(probe: MBIPlant, omega) -> np.ndarray:
    """The grid of the search (default :func:`_default_omega`), checked to cover the systems' modes."""
    omega = _default_omega(probe) if omega is None else np.asarray(omega, float)
    if omega.size == 0:
        raise ModelError("identify: the frequency grid is empty")
    if not np.all(np.isfinite(omega)) or omega.min() <= 0:
        raise ModelError("identify: the frequency grid must hold positive, finite frequencies (rad/s)")
    modes = np.abs(np.linalg.eigvals(np.asarray(probe.P.A, float)))
    modes = modes[modes > 0]
    if modes.size and (omega.max() < modes.min() / 10 or omega.min() > modes.max() * 10):
        raise ModelError(f"identify: no frequency overlap: the grid spans {omega.min():.4g}-{omega.max():.4g} "
                         f"rad/s, the systems' modes lie at {modes.min():.4g}-{modes.max():.4g} rad/s "
                         "(a decade either side is needed to compare their responses)")
    return omega


def _open_loop_difference(probe: MBIPlant, omega, excitation, measurement, Ww) -> float:
    """Peak open-loop error :math:`|x_t - x_e|` on the grid; an error if the two responses agree."""
    diff = float(np.max(np.abs(freqresp(probe.P, omega)[probe.nunc, probe.nunc])))
    E = probe.engineering
    ref = float(np.max(np.abs(freqresp(E, omega)[list(E.output_labels).index(measurement),
                                                 list(E.input_labels).index(excitation)]))) * Ww
    if diff <= 1e-9 * ref:
        raise IllPosedError("the true and engineering responses are identical on the grid "
                            f"(largest difference {diff:.3g} against {ref:.3g}): there is nothing to identify")
    return diff


def _first_wz(Wz, diff: float, floor: WzFloor):
    """The first W_z of the search (default 1 % of the open-loop error), kept above the floor; and notes."""
    notes = []
    if Wz is None:
        Wz = max(0.01 * diff, 1.1 * floor.value)
    elif Wz <= floor.value:
        notes.append(f"the first W_z {Wz:.4g} is below the floor {floor.value:.4g} set by the "
                     f"spread of the true systems at {floor.omega:.4g} rad/s (no controller can "
                     f"reach it); the search started at {1.1 * floor.value:.4g}")
        Wz = 1.1 * floor.value
    return Wz, notes


def _next_wz(tries, Wz: float, mu: float, lo, hi, target: float) -> float:
    """The log-log secant step toward ``mu = target`` (slope -1 on the first try), kept in ``(lo, hi)``."""
    if len(tries) >= 2 and tries[-1].Wz != tries[-2].Wz and tries[-1].mu_upper > 0 and tries[-2].mu_upper > 0:
        a, b = tries[-2], tries[-1]
        slope = (np.log(b.mu_upper) - np.log(a.mu_upper)) / (np.log(b.Wz) - np.log(a.Wz))
        slope = slope if slope < -0.05 else -1.0
    else:
        slope = -1.0
    new = Wz * np.exp((np.log(target) - np.log(max(mu, 1e-12))) / slope)
    if lo is not None and hi is not None:
        if not lo < new < hi:
            new = np.sqrt(lo * hi)
    elif lo is not None and new <= lo:
        new = lo * 1.1
    return float(new)


def _try_progress(progress, k: int, max_tries: int, Wz: float):
    """``progress`` for the D-K run of try ``k`` (0-based): its stages, within the try's share of the bar."""
    def report(stage, fraction):
        progress(f"{stage} (W_z try {k + 1}/{max_tries}, W_z = {Wz:.4g})", (k + fraction) / max_tries)
    return report


#: the D-K settings of each try (before ``dk_options``): coarse fits and no patience, since a
#: try only has to tell whether mu is below 1 at its W_z, and a K-step plant of at most 12 states
#: above the MBI plant's (its singular K steps go by the LMIs, whose cost grows steeply with it)
_TRY_DK = {"fit_tol": 0.02, "rel_improvement": 0.01, "patience": 1}
_TRY_EXTRA_STATES = 12


def _search_wz(plant_at, Wz: float, floor: WzFloor, omega, opts: dict, tol: float, max_tries: int,
               time_limit, t0: float, say, progress, real: bool = False, branch: bool = False) -> _WzSearch:
    r"""D-K runs at successive :math:`W_z` until :math:`1 - \text{tol} \le \mu \le 1` (see :func:`identify`)."""
    from ..dk import branch_mu, dgk_iteration, dk_iteration
    s = _WzSearch()
    lo = floor.value or None    # Wz with mu > 1 (too tight; the floor is one) / mu <= 1
    hi = None
    target = 1.0 - tol / 2
    for k in range(max_tries):
        if time_limit is not None and k > 0 and time.perf_counter() - t0 > time_limit:
            s.stopped_by_time = True
            break
        plant = plant_at(Wz)
        say(f"try {k + 1}: Wz = {Wz:.4g}")
        run_opts = opts
        if progress is not None:
            progress(f"W_z try {k + 1}/{max_tries}: W_z = {Wz:.4g}", k / max_tries)
            if "progress" not in opts:
                run_opts = {**opts, "progress": _try_progress(progress, k, max_tries, Wz)}
        ti = time.perf_counter()
        try:
            synth = dgk_iteration if real and plant.structure.has_real else dk_iteration
            res = synth(plant.P, plant.structure, 1, 1, omega=omega,
                        **{**_TRY_DK, "max_states": plant.P.nstates + _TRY_EXTRA_STATES, **run_opts})
        except (SolverError, InfeasibleError) as exc:
            # the controller construction is numerically erratic on some badly scaled plants: a
            # slightly looser W_z is a differently scaled plant, and the search goes on
            s.failed.append((Wz, str(exc)))
            say(f"       the K step failed at this W_z ({str(exc)[:90]}...); trying 7 % looser")
            Wz = float(Wz * 1.07)
            continue
        mu = float(max(res.mu_upper_dg, 0.0)) if np.isfinite(res.mu_upper_dg) else float(res.mu_upper)
        mu_dg = mu
        if branch and plant.structure.has_real and mu > 1.0 - tol:
            if progress is not None:
                progress(f"W_z try {k + 1}/{max_tries}: branch and bound on the real parameters",
                         (k + 0.95) / max_tries)
            mu = min(mu, branch_mu(res, plant.structure).value)
        s.tries.append(WzTry(Wz, mu, float(res.mu_lower), res.controller_order, time.perf_counter() - ti,
                             len(res.history), mu_dg))
        s.runs.append((plant, res))
        say(f"       mu <= {mu:.4f} (lower {res.mu_lower:.4f})"
            + (f"; D-G bound {mu_dg:.4f}" if mu < mu_dg else ""))
        if 1.0 - tol <= mu <= 1.0:
            break
        if mu > 1.0:
            lo = Wz if lo is None else max(lo, Wz)
        else:
            hi = Wz if hi is None else min(hi, Wz)
        Wz = _next_wz(s.tries, Wz, mu, lo, hi, target)
    if not s.runs:
        raise SolverError(f"identify: every D-K run failed ({len(s.failed)} W_z values from {s.failed[0][0]:.4g} "
                          f"to {s.failed[-1][0]:.4g}); the last: {s.failed[-1][1]}")
    return s


def _best_try(tries) -> int:
    """The smallest W_z with mu <= 1, else the lowest mu."""
    ok = [i for i, t in enumerate(tries) if t.mu_upper <= 1.0]
    return min(ok, key=lambda i: tries[i].Wz) if ok else int(np.argmin([t.mu_upper for t in tries]))


def _search_notes(search: _WzSearch, best: int, tol: float, max_tries: int, time_limit, t0: float) -> list:
    """A search that stopped outside the accepted window, and the budget used."""
    tries, notes = search.tries, []
    if not 1.0 - tol <= tries[best].mu_upper <= 1.0:
        ok = any(t.mu_upper <= 1.0 for t in tries)
        why = (f"the time limit of {time_limit:g} s was spent" if search.stopped_by_time
               else f"max_tries={max_tries} was reached")
        notes.append(f"W_z search stopped after {len(tries)} tries ({why}) without mu in [{1 - tol:.3g}, 1]; "
                     f"returning the try with {'the smallest W_z at mu <= 1' if ok else 'the lowest mu (> 1)'}")
    limit = "none" if time_limit is None else f"{time_limit:g} s"
    notes.append(f"budget: max_tries {max_tries}, time_limit {limit}; used {len(tries)} D-K run(s) in "
                 f"{time.perf_counter() - t0:.1f} s")
    return notes
