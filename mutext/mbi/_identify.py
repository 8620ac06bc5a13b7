r""":func:`identify`: the identification as a whole (a measured FRF or an uncertain model as the
true system, the first :math:`W_z` above the floor, the search, the reading of ``K``; the
convex route where it applies)."""
from __future__ import annotations

import time
from collections.abc import Callable
import numpy as np

from ..errors import ModelError
from ..lti import as_ss
from ..response import FRF
from ._measured import _measured_notes
from ._plant import controlled_engineering
from ._result import MBIResult, _fit_on_identifiable_band, _logger
from ._search import _best_try, _search_notes, _search_wz, _WzSearch
from ._start import _Start, _start


def identify(true, engineering, *, excitation: str, measurement: str, control_input: str,
             control_output: str, Ww: float = 1.0, Wz: float | None = None, tol: float | None = None,
             max_tries: int | None = None, regularization: float | None = 1e-4, omega=None,
             dk_options: dict | None = None, out=None, time_limit: float | None = None,
             max_fit_residual: float = 0.2, progress: Callable[[str, float], None] | None = None,
             real: bool = False, branch: bool = False, weight: str = "flat", method: str = "auto") -> MBIResult:
    r"""Identify the unmodeled dynamics of ``engineering`` by mu-synthesis (thesis sec. 3.5).

    ``method="convex"`` solves the same problem as a convex program in the Youla parameter of
    the controller instead (:func:`identify_convex`; Boyd and Barratt, 1991): the smallest
    :math:`W_z` the controllers of a rational basis reach on samples of the true set, then a
    certificate.  On trials 1a-5 of the thesis and on the cracked rotor it certifies a smaller
    :math:`W_z` than the D-K search, in less time, with a controller of higher order
    (``benchmarks/bench_mbi_convex.py``), so the default ``method="auto"`` takes it wherever
    it applies: a stable engineering model and none of the D-K search's own options (``Wz``,
    ``regularization``, ``dk_options``, ``real``, ``branch``) given.  ``method="dk"`` is the
    search described below.

    Runs D-K iteration on the plant of :func:`mbi_plant` and tunes :math:`W_z`
    by the thesis's step-7 rule, automated: :math:`\mu > 1` means the bound is
    too tight (raise :math:`W_z`), :math:`\mu < 1 - \text{tol}` too loose (lower
    it).  Each new value comes from the log-log secant through the last two tries
    (:math:`\mu` scales roughly like :math:`W_z^{-1}`), kept inside the bracket
    once one is known.  Accepted: :math:`1 - \text{tol} \le \mu \le 1`.  No try goes
    below the floor of :func:`wz_floor`, under which :math:`\mu > 1` for every
    controller.

    Parameters
    ----------
    true : control.StateSpace, mutext.uncertain.UncertainModel or mutext.rig.FRF
        As in :func:`mbi_plant`, or a measured FRF from the excitation to the
        measurement (SI units), which :func:`true_from_frf` fits by a stable
        rational model; the grid is then the measured frequencies.
    engineering, excitation, measurement, control_input, control_output, Ww, regularization
        As in :func:`mbi_plant`.
    Wz : float, optional
        First value to try (default: 1 % of the peak open-loop error
        :math:`W_w|x_t - x_e|`, or 1.1 times the floor if that is larger; a
        value at or below the floor is raised to it, with a note).
    tol : float, optional
        Accepted distance of mu below 1 (default 0.05; with ``method="convex"``, 0.01).
    max_tries : int, optional
        Largest number of D-K runs (default 8; with ``method="convex"``, of certificates: 6).
    omega : array_like, optional
        Frequency grid (rad/s) for the D steps, the identifiable band and the fit.
    dk_options : dict, optional
        Passed to :func:`mutext.dk.dk_iteration` (or :func:`mutext.dk.dgk_iteration`).
    out : file or None
        A log of the search (one line per try, and the D-K tables); default
        None: silent.
    progress : callable(stage: str, fraction: float), optional
        Called during the W_z search (e.g. :class:`mutext.progress.ProgressLine`):
        the D-K stage of each try (passed on to :func:`mutext.dk.dk_iteration`
        unless ``dk_options`` gives its own ``progress``) and the try's
        :math:`W_z`, with the fraction of ``max_tries`` spent; the fraction
        reaches 1 at the end.
    time_limit : float, optional
        Budget in seconds: no new D-K run is started once it is spent (a run
        under way is finished).  The notes of the result report the budget and
        what was used.
    max_fit_residual : float
        For a measured FRF: largest RMS relative residual of its rational fit
        (:func:`true_from_frf`) for which identification goes on.
    real : bool
        Design each try's controller with the uncertain parameters kept real
        (:func:`mutext.dk.dgk_iteration`) instead of plain D-K.  On trial 5
        (10 % uncertainty) it accepts the same :math:`W_z` (4.86 mm), in seven
        times the time: there D-K keeps its first, H-infinity, loop, whose
        D-G bound the later iterations only raise.
    branch : bool
        Judge each try whose D-G bound could decide it (above ``1 - tol``) by
        branch and bound on the real parameters (:func:`mutext.dk.branch_mu`),
        a certified bound that closes the D-G bound's gap to :math:`\mu` where
        the ranges are wide.  On trial 5 (10 % uncertainty) the search then
        accepts 4.72 mm at :math:`\mu` = 0.993, where the D-G bound reads 1.003
        (against 4.86 mm judged by D-G): it can accept values the D-G bound
        rejects.  Each judged try costs some seconds more.
    weight : {"flat", "spread"}
        The frequency shape of the error bound.  ``"flat"`` (the thesis's):
        the error may reach :math:`W_z` at every frequency.  ``"spread"``: the
        bound :math:`W_z|S(j\omega)|` follows the spread of the true systems
        (:func:`spread_weight`; needs an uncertain true model), so that ``K``
        is held wherever the true set is narrow, not only where it is widest.
        With wide uncertainty this is what lets ``K`` be read: on trial 5
        (10 %) a flat bound holds ``K`` on 4.5-7.1 rad/s only (the spring read
        to +/-85 N/m), the shaped one over 0.5-32 rad/s (+/-5 N/m).  :math:`W_z` is then the bound
        at the widest spread, and the floor is the floor of the shaped bound.
    method : {"auto", "dk", "convex"}
        ``"auto"`` (default): ``"convex"`` for a stable engineering model when none of the
        D-K-only options is given, else ``"dk"``.  ``"dk"``: the :math:`W_z` search by D-K
        iteration (above).  ``"convex"``:
        :func:`identify_convex` (needs a stable engineering model; ``Wz``,
        ``regularization``, ``dk_options``, ``real`` and ``branch`` do not apply and must keep
        their defaults; ``tol`` and ``max_tries`` are those of its certificate).

    Raises
    ------
    ModelError
        ``max_tries`` not a positive integer, ``time_limit`` not positive,
        a measured FRF that cannot be fitted (see :func:`true_from_frf`), no
        frequency overlap, a bad grid.

    Returns
    -------
    MBIResult
        If no try reached the accepted window, the best try with mu <= 1 (or the
        lowest mu) is returned with a note saying so.

    Examples
    --------
    Trial 1a of the thesis: the engineering model's spring ``k3`` is 200 N/m,
    the rig's 386 N/m.  One D-K run of one K step (a few seconds, most of it the
    synthesis; the final analysis on 20 points, the uncertain spring's real
    parameter bounded as a complex one, ``dg=False``) finds the difference:

    >>> from mutext.examples import three_mass as tm
    >>> from mutext.mbi import identify
    >>> trial = tm.TRIALS["1a"]
    >>> r = identify(**tm.mbi_arguments(trial), max_tries=1,
    ...              dk_options={"max_iter": 1, "final_points": 20, "dg": False})
    >>> round(r.fit.dk), trial.Du["dk"]                # the spring K stands for [N/m]
    (186, 186.0)
    >>> bool(r.mu_upper <= 1)                           # the error bound W_z is certified
    True
    """
    if method == "auto":
        method = "convex" if _convex_applies(engineering, Wz, regularization, dk_options, real, branch) else "dk"
    if method == "convex":
        return _identify_convex(true, engineering, excitation, measurement, control_input, control_output, Ww,
                                Wz, tol, max_tries, regularization, omega, dk_options, out, time_limit,
                                max_fit_residual, progress, real, branch, weight)
    if method != "dk":
        raise ModelError(f"identify: method must be 'auto', 'dk' or 'convex', got {method!r}")
    t0 = time.perf_counter()
    tol = 0.05 if tol is None else tol
    max_tries = 8 if max_tries is None else max_tries
    _check_search_arguments(max_tries, time_limit, tol, real, branch, weight, true)
    say = _logger(out)
    kw = dict(excitation=excitation, measurement=measurement, control_input=control_input,
              control_output=control_output, Ww=Ww, regularization=regularization)
    start = _start(true, engineering, kw, omega, Wz, weight, max_fit_residual, say)
    search = _search_wz(start.plant_at, start.Wz, start.floor, start.omega, _dk_options(out, dk_options), tol,
                        max_tries, time_limit, t0, say, progress, real, branch)
    return _result(search, start, tol, max_tries, time_limit, t0, progress)


def _dk_only(Wz, regularization, dk_options, real, branch) -> list:
    """Names of the options of the D-K search given other than their defaults."""
    return [name for name, v, default in (("Wz", Wz, None), ("regularization", regularization, 1e-4),
                                          ("dk_options", dk_options, None), ("real", real, False),
                                          ("branch", branch, False)) if v is not default and v != default]


def _convex_applies(engineering, Wz, regularization, dk_options, real, branch) -> bool:
    """``method="auto"``: the convex route for a stable engineering model without D-K-only options."""
    from ..lti import is_stable
    if _dk_only(Wz, regularization, dk_options, real, branch):
        return False
    try:
        E = as_ss(engineering, "engineering model")
        return bool(E.nstates == 0 or is_stable(E))
    except Exception:      # noqa: BLE001 - the D-K route reports a malformed model in its own words
        return False


def _identify_convex(true, engineering, excitation, measurement, control_input, control_output, Ww, Wz, tol,
                     max_tries, regularization, omega, dk_options, out, time_limit, max_fit_residual, progress,
                     real, branch, weight):
    """:func:`identify` with ``method="convex"``: the D-K options refused, the rest passed on."""
    from ._convex import identify_convex
    given = _dk_only(Wz, regularization, dk_options, real, branch)
    if given:
        raise ModelError(f"identify: {', '.join(given)} belong(s) to method='dk'; method='convex' finds the "
                         "smallest W_z itself and certifies it on the unregularised plant")
    return identify_convex(true, engineering, excitation=excitation, measurement=measurement,
                           control_input=control_input, control_output=control_output, Ww=Ww, omega=omega,
                           weight=weight, tol=0.01 if tol is None else tol,
                           max_tries=6 if max_tries is None else max_tries, max_fit_residual=max_fit_residual,
                           time_limit=time_limit, out=out, progress=progress)


def _dk_options(out, dk_options) -> dict:
    """The options of each try's D-K run: 4 iterations, the log on ``out``, then ``dk_options`` (checked)."""
    opts = {"max_iter": 4, "out": None if out is None else out}
    if dk_options is not None and not isinstance(dk_options, dict):
        raise ModelError(f"dk_options must be a dict of dk_iteration's keyword arguments, got "
                         f"{type(dk_options).__name__}")
    import inspect

    from ..dk import dgk_iteration, dk_iteration
    # the options go to dk_iteration, or to dgk_iteration when real parameters are kept real
    known = (set(inspect.signature(dk_iteration).parameters) | set(inspect.signature(dgk_iteration).parameters)) \
        - {"P", "structure", "nmeas", "ncon"}
    unknown = sorted(set(dk_options or {}) - known)
    if unknown:
        raise ModelError(f"dk_options: unknown option(s) {', '.join(map(repr, unknown))}; dk_iteration and "
                         f"dgk_iteration take {', '.join(sorted(known))}")
    opts.update(dk_options or {})
    return opts


def _result(search: _WzSearch, start: _Start, tol: float, max_tries: int, time_limit, t0: float,
            progress) -> MBIResult:
    """The result of the search's best try: its controller, read on its identifiable band, with the notes."""
    best = _best_try(search.tries)
    plant, res = search.runs[best]
    notes = start.notes
    if search.failed:
        notes.append(f"the K step failed at {len(search.failed)} W_z value(s) ("
                     + ", ".join(f"{w:.4g}" for w, _ in search.failed) + "); the search moved on to looser ones")
    if start.measured_fit is not None:
        notes += _measured_notes(plant, res, start.measured, start.measured_fit)
    notes += _search_notes(search, best, tol, max_tries, time_limit, t0)
    judged = [t for t in search.tries if t.mu_upper < t.mu_dg]
    if judged:
        notes.append(f"branch and bound on the real parameters judged {len(judged)} of {len(search.tries)} "
                     f"tries below their D-G bound (accepted W_z: mu {search.tries[best].mu_upper:.4f}, "
                     f"D-G {search.tries[best].mu_dg:.4f})")
    if plant.eps_u or plant.eps_y:
        notes.append(f"regularised: control penalty {plant.eps_u:.3g} per unit u, sensor noise "
                     f"{plant.eps_y:.3g} (the thesis plant is singular)")
    fit = _fit_on_identifiable_band(plant, res.K, start.omega, notes)
    if progress is not None:
        progress(f"W_z search done: W_z = {search.tries[best].Wz:.4g}, mu <= {search.tries[best].mu_upper:.4f}",
                 1.0)
    tries = search.tries
    return MBIResult(res.K, tries[best].Wz, tries[best].mu_upper, tries[best].mu_lower, tries, plant, fit,
                     controlled_engineering(plant, res.K), res, time.perf_counter() - t0, start.omega, notes,
                     start.floor, start.measured_fit)


def _check_search_arguments(max_tries, time_limit, tol, real, branch, weight, true) -> None:
    """The options of :func:`identify`'s search, checked (``true`` for ``weight="spread"``)."""
    if isinstance(max_tries, (bool, np.bool_)) or not isinstance(max_tries, (int, np.integer)) or max_tries < 1:
        raise ModelError(f"identify: max_tries must be a positive integer (the number of D-K runs allowed), "
                         f"got {max_tries!r}")
    if time_limit is not None and (isinstance(time_limit, (bool, np.bool_))
                                   or not isinstance(time_limit, (int, float, np.integer, np.floating))
                                   or not time_limit > 0):
        raise ModelError(f"identify: time_limit must be a positive number of seconds or None, got {time_limit!r}")
    if not (isinstance(tol, (int, float, np.integer, np.floating)) and 0 < tol < 1):
        raise ModelError(f"identify: tol must lie in (0, 1), got {tol!r}")
    if not isinstance(real, (bool, np.bool_)):
        raise ModelError(f"identify: real must be True or False, got {real!r}")
    if not isinstance(branch, (bool, np.bool_)):
        raise ModelError(f"identify: branch must be True or False, got {branch!r}")
    if weight not in ("flat", "spread"):
        raise ModelError(f"identify: weight must be 'flat' or 'spread', got {weight!r}")
    if weight == "spread" and isinstance(true, FRF):
        raise ModelError("identify: weight='spread' follows the spread of an uncertain true model; a measured "
                         "FRF has none (use weight='flat')")
