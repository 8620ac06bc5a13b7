r"""D-K iteration: the result, the checked options and the loop of K steps and D steps."""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import control as ct
import numpy as np

from ..errors import IllPosedError, InfeasibleError, ModelError, SolverError
from ..lti import as_ss, blas_single_thread, freqresp, lft_lower
from ..mu import BlockStructure, MuSweep
from ._dscale import _check_sizes, scaled_plant
from ._dstep import _d_step, _sweep_upper
from ..hinf import hinfsyn
from ._kstep import _k_step, _k_step_lmi_first, _k_step_riccati
from ._report import _Heartbeat, _print
from ._sweep import _default_dk_grid, _dg_peak, _final_analysis, near_axis_poles


@dataclass
class DKResult:
    r"""Result of :func:`dk_iteration`.

    Attributes
    ----------
    K : control.StateSpace
        The controller of the best iteration (lowest peak mu upper bound on the
        grid; with real blocks and ``dg``, lowest D-G bound).
    CL : control.StateSpace
        :math:`\mathcal F_\ell(P, K)`, the unscaled closed loop.
    mu_upper : float
        Peak over a fine, refined grid of the upper bound with optimal
        (unfitted) D scalings at each frequency, real parameters treated as
        complex.  Each point is :math:`\bar\sigma(DMD^{-1})` for an explicit
        :math:`D`, hence a certified bound at that frequency.
    mu_upper_dg : float
        Upper bound for the structure with its real blocks: the peak over
        the final grid of the lower of the D-G bound
        (``mutext.mu.mu_upper(method="fast")``, computed from the largest
        complex values down until the next cannot raise the peak)
        and the complex bound, with the eight largest local maxima of the D-G
        bound within 2 % of its peak refined by 6 frequencies each, then the
        four largest within 0.2 % (a loop that
        exploits the real parameters equalises the D-G bound, and its peak
        can lie between the points refined for the complex bound); equal to
        ``mu_upper`` without real blocks or with ``dg=False``.
    mu_lower : float
        Peak lower bound for the structure as given (real blocks real); a
        perturbation achieving it is ``sweep.lower_delta``.
    mu_lower_complex : float
        Peak lower bound with real blocks treated as complex (the quantity
        ``mu_upper`` bounds from above).
    peak_frequency : float
        Frequency (rad/s) of ``mu_upper``.
    history : list of dict
        Per iteration: ``iteration``, ``gamma`` (K-step level), ``mu`` (peak
        upper bound on the D-step grid, real parameters as complex),
        ``mu_dg`` (the same with D-G scalings for the real blocks:
        ``mutext.mu.mu_upper(method="fast")`` from the largest complex values
        down, capped pointwise by the complex bound; equal to ``mu`` without
        real blocks or with ``dg=False``), ``orders`` (D-fit orders used in
        that K step), ``g_orders`` (G-fit orders of the real blocks: None,
        the K steps scale real blocks as complex), ``real_scale`` (the
        factor on the real parameters' ranges in the K step: 1, or the try's
        :math:`c` in :func:`dgk_iteration`), ``plant_states``
        (states of the scaled K-step plant), ``fit_peak`` (peak of the
        fitted-scaled closed loop of the previous controller, the level the K
        step starts from), ``controller_order``, ``method`` (how the K step's
        controller was built: ``"central"``, our Riccati central controller;
        ``"lmi"``, our LMI reconstruction; ``"slycot"``, slycot's synthesis,
        verified), ``seconds``.
    sweep : MuSweep
        Final fine-grid analysis (complex upper bound; lower bound fields
        for the given structure).
    fits : list
        D-scale fits used in the best controller's K step.
    seconds : float
    best_iteration : int
    notes : list of str
    near_axis_poles : ndarray
        Poles of ``P`` that :func:`near_axis_poles` sets apart (e.g. a
        performance weight's pole at -1e-6 rad/s); empty if none.  The D-step
        grid leaves them out, the final analysis covers them.
    max_pole_real : float
        Largest real part of the poles of ``CL`` (the loop of the plant as
        given, not of any modified plant): negative means stable.
    real_scale : float
        :func:`dgk_iteration`: the factor :math:`c` by which the K steps of
        the returned controller saw the ranges of the real parameters
        (1: plain D-K).
    tries : list of dict
        :func:`dgk_iteration`: one row per factor tried (``scale``,
        ``mu_dg`` and ``mu`` of the loop of the plant as given, ``mu_lower``,
        ``controller_order``, ``iterations``, ``seconds``); empty for
        :func:`dk_iteration`.
    """
    K: ct.StateSpace
    CL: ct.StateSpace
    mu_upper: float
    mu_upper_dg: float
    mu_lower: float
    mu_lower_complex: float
    peak_frequency: float
    history: list
    sweep: MuSweep
    fits: list
    seconds: float
    best_iteration: int = 0
    notes: list = field(default_factory=list)
    near_axis_poles: np.ndarray = field(default_factory=lambda: np.zeros(0, complex))
    max_pole_real: float = float("nan")
    real_scale: float = 1.0
    tries: list = field(default_factory=list)

    @property
    def controller_order(self) -> int:
        """Number of states of ``K``."""
        return self.K.nstates


#: default K-step budget above the plant's order (``max_states``): room for order-4 fits of
#: four scalar blocks, as the thesis's two-mass problem needs to reach its best D scalings
_DEFAULT_EXTRA_STATES = 32


def dk_iteration(P, structure: BlockStructure, nmeas: int, ncon: int, *, omega=None,
                 max_iter: int = 20, max_order: int = 4, max_states: int | None = None,
                 fit_tol: float = 5e-4, rel_improvement: float = 1e-3, patience: int = 2,
                 grid_points: int = 80, final_points: int = 200, dg: bool = True,
                 synthesis=None, out=None, progress=None) -> DKResult:
    r"""D-K iteration for robust performance.

    Parameters
    ----------
    P : control.StateSpace
        Generalized plant, inputs ``[w_Delta; u]`` and outputs ``[z_Delta; y]``,
        where the ``Delta`` channels follow ``structure`` (the performance block
        included, normally last: the last block's scaling is fixed to 1).
    structure : BlockStructure
    nmeas, ncon : int
        Number of measurements (last outputs) and controls (last inputs).
    omega : array_like, optional
        Grid for the D steps (default: ``grid_points`` log-spaced frequencies
        1.5 decades beyond the plant's poles, plus its resonances; poles
        near the axis, :func:`near_axis_poles`, left out).  The fitted
        scalings keep their poles and zeros inside it.
    max_iter : int
        Largest number of K steps.
    max_order : int
        Largest D-fit order per block (0-5).
    max_states : int, optional
        Largest number of states of the K-step plant, ``P.nstates`` plus
        ``(rows + cols) * order`` per block (default ``P.nstates + 32``).  The
        cost of an LMI K step grows steeply with it; the D step gives the
        states to the blocks whose fits are worst.
    fit_tol : float
        Relative slack of the D fits: the fitted scalings keep the scaled
        closed loop below ``(1 + fit_tol)`` times the peak of mu on the grid.
    rel_improvement : float
        An iteration counts as progress if it lowers the best peak mu by at
        least this fraction.
    patience : int
        Stop after this many iterations without progress.
    grid_points : int
        Size of the default D-step grid.
    final_points : int
        Points of the final analysis grid (before peak refinement).
    dg : bool
        Also compute the D-G (mixed real) bound of the final closed loop.
    synthesis : {"lmi", "lmi-first", "riccati"} or callable, optional
        The K step.  ``"lmi"`` (default; the name is historical):
        :func:`mutext.hinf.hinfsyn`, our own synthesis (the Riccati central
        controller where the Riccati solutions exist, the LMIs otherwise), the
        controller built 0.1 % above the optimal level, with slycot's Riccati
        synthesis as a verified fallback.  ``"lmi-first"``: the LMI controller
        where it passes its check, the default otherwise (the K step's
        controller is not unique, and in model-based identification the
        controller *is* the result: on the three-mass trial 5 with the
        error bound shaped by the spread of the true rigs, the central
        controller certifies 6.0 mm, the LMI one 26 mm).  ``"riccati"``: slycot first (much
        faster on K-step plants of 15 states and more), accepted only when
        :func:`mutext.hinf.slycot_hinfsyn` verifies it, hinfsyn otherwise.  A
        callable ``synthesis(PD, nmeas, ncon)`` must return an object with
        ``K`` and ``gamma``.
    out : file or None
        Where the per-iteration table is printed (default None: silent; the demos pass sys.stderr).
        Columns: iteration, K-step level, peak mu on the grid (and with real
        blocks its D-G bound), the D-fit orders of the scalings used in
        that K step (and, with real blocks, how the K step saw them:
        "complex", or "c = ..." for the scaled ranges of a
        :func:`dgk_iteration` try), controller order, states of the scaled
        plant and seconds.
    progress : callable, optional
        ``progress(stage, fraction)``, called during the slow steps (e.g.
        :class:`mutext.progress.ProgressLine`): the K step (``"K-step ..."``;
        the SDP solve cannot report itself, so a helper thread calls
        ``progress`` about once a second with the elapsed time), the mu sweep
        over the grid (``"mu-sweep ..."``, with the fraction of frequencies
        converged), the D fits (``"D-fit ..."``, one call per fit) and the
        final analysis (``"final-analysis ..."``).  ``fraction`` is the
        overall fraction done (iterations up to ``max_iter`` share 0-0.9).

    Returns
    -------
    DKResult

    Raises
    ------
    ModelError
        Plant and structure sizes that do not match, an empty or invalid grid,
        invalid options.
    IllPosedError, InfeasibleError, SolverError
        The first K step failed (later failures end the iteration and keep the
        best controller found, with a note).

    Examples
    --------
    Robust performance of the thesis's two-mass problem with the bound on
    :math:`x_1` at 0.043 m and +/-2 % on every parameter: two K steps on a
    coarse grid of 12 frequencies, the real parameters bounded as complex ones
    (``dg=False``; about a second).  The first, H-infinity, controller leaves
    :math:`\mu` at 3.03; the second, with the fitted D scalings, brings it
    below 1 (the defaults, up to twenty iterations on 80 points and the D-G
    bound, reach 0.979 with 30 states in about 14 s):

    >>> from mutext.examples import two_mass_uncertain as tmu
    >>> P = tmu.plant(0.043)
    >>> res = dk_iteration(P, tmu.structure(), 1, 1, max_iter=2, grid_points=12, final_points=12,
    ...                    dg=False)
    >>> round(res.history[0]["mu"], 2), bool(res.mu_upper < 1), bool(res.mu_lower <= res.mu_upper)
    (3.03, True, True)
    >>> res.controller_order <= P.nstates + 32
    True
    """
    t0 = time.perf_counter()
    P, S, args = _arguments(P, structure, nmeas, ncon, omega, max_iter, max_order, max_states, fit_tol,
                            rel_improvement, patience, grid_points, final_points, dg, synthesis)
    with blas_single_thread():
        return _dk(P, S, nmeas, ncon, *args, out, t0, progress)


def _arguments(P, structure, nmeas, ncon, omega, max_iter, max_order, max_states, fit_tol,
               rel_improvement, patience, grid_points, final_points, dg, synthesis):
    """Checked options of :func:`dk_iteration`: the plant, the structure and the positional
    arguments of :func:`_dk` from ``grid`` to ``synth``."""
    P = as_ss(P, "P")
    if not isinstance(structure, BlockStructure):
        raise ModelError(f"structure must be a BlockStructure, got {type(structure).__name__}")
    S = structure
    _check_sizes(P, S, nmeas, ncon)
    if not (isinstance(max_order, (int, np.integer)) and 0 <= max_order <= 5):
        raise ModelError(f"max_order must be an integer between 0 and 5, got {max_order!r}")
    if not (isinstance(max_iter, (int, np.integer)) and max_iter >= 1):
        raise ModelError(f"max_iter must be a positive integer, got {max_iter!r}")
    if max_states is None:
        max_states = P.nstates + _DEFAULT_EXTRA_STATES
    if not (isinstance(max_states, (int, np.integer)) and max_states >= P.nstates):
        raise ModelError(f"max_states must be an integer >= the plant order {P.nstates}, got {max_states!r}")
    if not fit_tol > 0:
        raise ModelError(f"fit_tol must be positive, got {fit_tol!r}")
    for name, v, least in (("patience", patience, 1), ("grid_points", grid_points, 3),
                           ("final_points", final_points, 3)):
        if not (isinstance(v, (int, np.integer)) and v >= least):
            raise ModelError(f"{name} must be an integer >= {least}, got {v!r}")
    if omega is not None:
        omega = np.unique(np.asarray(omega, dtype=float).ravel())
        if omega.size == 0:
            raise ModelError("the frequency grid omega is empty")
        if not (np.all(np.isfinite(omega)) and np.all(omega > 0)):
            raise ModelError("the frequency grid omega must hold positive, finite frequencies (rad/s)")
    if synthesis is None or synthesis == "lmi":
        synth = _k_step
    elif synthesis == "riccati":
        synth = _k_step_riccati
    elif synthesis == "lmi-first":
        synth = _k_step_lmi_first
    elif callable(synthesis):
        synth = synthesis
    else:
        raise ModelError(f"synthesis must be 'lmi', 'lmi-first', 'riccati' or a callable, got {synthesis!r}")
    return P, S, (omega, max_iter, max_order, max_states - P.nstates, fit_tol, rel_improvement, patience,
                  grid_points, final_points, dg, synth)


class _Steps:
    """The K and D steps of one D-K run on the grid ``grid``, with their progress reports
    (``on_progress(stage, fraction)``; iterations up to ``max_iter`` share 0-0.9)."""

    def __init__(self, S, nmeas, ncon, grid, max_iter, fit_tol, budget, synth, on_progress):
        self.S, self.Sc, self.nmeas, self.ncon, self.grid = S, S.complexified(), nmeas, ncon, grid
        self.max_iter, self.fit_tol, self.budget, self.synth = max_iter, fit_tol, budget, synth
        self.on_progress = on_progress

    def at(self, it, part):
        """Overall fraction at ``part`` (0-1) of iteration ``it``."""
        return 0.9 * (it - 1 + part) / self.max_iter

    def report(self, stage, fraction):
        if self.on_progress is not None:
            self.on_progress(stage, min(max(fraction, 0.0), 1.0))

    def kstep(self, it, PD):
        """The synthesis of iteration ``it`` on the scaled plant ``PD``, with a heartbeat."""
        stage = (lambda el: f"K-step {it}/{self.max_iter}: H-infinity synthesis, {PD.nstates} states, {el:.0f} s")
        with _Heartbeat(self.on_progress, stage, self.at(it, 0.0)):
            return self.synth(PD, self.nmeas, self.ncon)

    def dstep(self, it, H, X, upper, order):
        """Rational scalings of order up to ``order`` for the loop ``H`` (:func:`_d_step`)."""
        return _d_step(self.grid, H, self.S, X, upper, order, self.fit_tol, self.budget,
                       progress=lambda text: self.report(f"D-fit {it}/{self.max_iter}: {text}", self.at(it, 0.9)))

    def sweep(self, it, H, X):
        """The complex bound on the grid, warm-started from the log scalings ``X``."""
        return _sweep_upper(H, self.Sc, X, progress=lambda f: self.report(
            f"mu-sweep {it}/{self.max_iter}: {self.grid.size} frequencies, {100 * f:.0f} % converged",
            self.at(it, 0.6 + 0.3 * f)))


@dataclass
class _DKState:
    """What one iteration hands the next: the scalings (fitted and pointwise), the last loop's
    response and bound on the grid, and the best loop so far as ``(mu, K, CL, fits, iteration)``."""
    fits: list
    Xd: np.ndarray | None = None        # log D scalings on the grid, the next sweep's starting point
    H: np.ndarray | None = None
    upper: np.ndarray | None = None
    fit_peak: float = float("nan")
    history: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    best: tuple | None = None
    best_plant: object = None           # the scaled plant of the best loop's K step
    lowest: float | None = None
    stall: int = 0


class _Table:
    """The per-iteration table printed to ``out`` (see :func:`dk_iteration`)."""

    def __init__(self, out, S, dg, real_scale):
        self.out = out
        self.real_blocks = [k for k, b in enumerate(S.blocks) if b.kind == "real"]
        self.gcol = f" {'real blocks':>11}" if self.real_blocks else ""
        self.gtxt = (f" {'complex' if real_scale == 1.0 else f'c = {real_scale:.3f}':>11}"
                     if self.real_blocks else "")
        self.dgcol = f" {'mu D-G':>8}" if self.real_blocks and dg else ""

    def header(self):
        _print(self.out, f"{'iter':>4} {'gamma (K step)':>15} {'peak mu':>10}{self.dgcol} {'D-fit orders':>18}"
                         f"{self.gcol} {'K order':>8} {'plant':>6} {'seconds':>8}")

    def row(self, it, gamma, mu_pk, mu_dg_pk, orders, K, PD, seconds):
        dgtxt = f" {mu_dg_pk:>8.5f}" if self.dgcol else ""
        _print(self.out, f"{it:>4} {gamma:>15.5f} {mu_pk:>10.5f}{dgtxt} {str(orders):>18}{self.gtxt} "
                         f"{K.nstates:>8} {PD.nstates:>6} {seconds:>8.2f}")


def _k_step_retried(steps: _Steps, P, st: _DKState, it, orders):
    """The K step of iteration ``it`` on ``P`` scaled by ``st.fits``; if it fails after a D step
    with fitted scalings, once more with scalings one order lower (they spread the scaled
    plant's eigenvalues less, which is what usually defeats the LMI solver; ``st.fits``
    follows the retry).  Returns the synthesis result (None if it failed), the scaled plant,
    the orders used and the error; the first K step's error is raised."""
    S, nmeas, ncon = steps.S, steps.nmeas, steps.ncon
    PD = P if it == 1 else scaled_plant(P, S, st.fits, nmeas, ncon)
    try:
        return steps.kstep(it, PD), PD, orders, None
    except (InfeasibleError, SolverError, IllPosedError) as exc:
        if st.best is None:
            raise
        if not any(orders):
            return None, PD, orders, exc
        first = f"iteration {it}: the K step failed with D-fit orders {orders} ({exc})"
    try:
        st.fits, st.fit_peak = steps.dstep(it, st.H, st.Xd, st.upper, max(orders) - 1)
        orders = [f.order for f in st.fits[:-1]]
        PD = scaled_plant(P, S, st.fits, nmeas, ncon)
        res = steps.kstep(it, PD)
    except (InfeasibleError, SolverError, IllPosedError) as exc:
        return None, PD, orders, exc
    st.notes.append(first + f"; retried with orders {orders}")
    return res, PD, orders, None


def _record_failure(st: _DKState, table: _Table, it, exc, PD, orders, real_scale, ti):
    """A failed K step after a good one: a note and a history row; the run stops there."""
    st.notes.append(f"iteration {it}: the K step failed ({exc}); kept iteration {st.best[4]}")
    st.history.append({"iteration": it, "gamma": float("nan"), "mu": float("nan"),
                       "mu_dg": float("nan"), "orders": orders,
                       "g_orders": [None] * len(table.real_blocks), "real_scale": real_scale,
                       "plant_states": int(PD.nstates), "fit_peak": st.fit_peak, "controller_order": None,
                       "method": None, "seconds": time.perf_counter() - ti, "error": str(exc)})
    msg = str(exc)
    _print(table.out, f"{it:>4}  K step failed: {msg[:90] + ' ...' if len(msg) > 90 else msg}")


def _iteration(steps: _Steps, P, st: _DKState, table: _Table, it, max_order, rel_improvement, patience,
               dg, real_scale) -> bool:
    """One K step and the analysis of its loop on the grid, then (unless the run stops) the D
    step for the next.  Updates ``st``; returns True when the run stops."""
    S, nmeas, ncon = steps.S, steps.nmeas, steps.ncon
    ti = time.perf_counter()
    orders = [0 if f is None else f.order for f in st.fits[:-1]]
    res, PD, orders, exc = _k_step_retried(steps, P, st, it, orders)
    if res is None:
        _record_failure(st, table, it, exc, PD, orders, real_scale, ti)
        return True
    K = as_ss(res.K, "K")
    CL = lft_lower(P, K, nmeas, ncon)
    max_re = _max_pole_real(CL)
    if max_re >= 0:
        # D-hat is stable and minimum phase, so K stabilises P iff it stabilises D P D^-1
        exc = SolverError(f"iteration {it}: the K-step controller does not stabilise the plant "
                          f"(closed-loop pole with real part {max_re:.3g})")
        if st.best is None:
            raise exc
        st.notes.append(str(exc))
        _print(table.out, f"{it:>4}  {exc}")
        return True
    st.H = np.moveaxis(freqresp(CL, steps.grid), -1, 0)
    st.upper, st.Xd = steps.sweep(it, st.H, st.Xd)
    mu_pk = float(st.upper.max())
    mu_dg_pk = mu_pk
    if table.real_blocks and dg:
        # the bound with the real blocks real (fast D-G sweep, no LMI check), pointwise
        # no higher than the complex one: both are certified at each frequency
        steps.report(f"mu-sweep {it}/{steps.max_iter}: D-G bound at the peaks", steps.at(it, 0.9))
        mu_dg_pk = _dg_peak(st.H, S, st.upper)[0]
    row = {"iteration": it, "gamma": float(res.gamma), "mu": mu_pk, "mu_dg": mu_dg_pk, "orders": orders,
           "g_orders": [None] * len(table.real_blocks), "real_scale": real_scale,
           "plant_states": int(PD.nstates), "fit_peak": st.fit_peak, "controller_order": int(K.nstates),
           "method": getattr(res, "method", "custom"),
           "seconds": time.perf_counter() - ti}
    st.history.append(row)
    progress = st.lowest is None or mu_pk < st.lowest * (1.0 - rel_improvement)
    st.lowest = mu_pk if st.lowest is None else min(st.lowest, mu_pk)
    # the loop kept is the one with the lowest bound that will be reported: with real blocks,
    # the D-G bound (a D step that lowers the complex bound can raise it: the fitted D scalings
    # treat the real parameters as complex)
    if st.best is None or mu_dg_pk < st.best[0]:
        st.best = (mu_dg_pk, K, CL, list(st.fits), it)
        st.best_plant = PD
    st.stall = 0 if progress else st.stall + 1
    # a single block has no scaling to fit: the first K step is the answer
    stop = st.stall >= patience or it == steps.max_iter or len(S) == 1
    if not stop:
        # D step on the new closed loop
        try:
            fits_new, st.fit_peak = steps.dstep(it, st.H, st.Xd, st.upper, max_order)
        except SolverError as exc:
            st.notes.append(f"iteration {it}: {exc}")
            stop = True
        else:
            st.fits = fits_new
    row["seconds"] = time.perf_counter() - ti
    table.row(it, res.gamma, mu_pk, mu_dg_pk, orders, K, PD, row["seconds"])
    return stop


def _dk(P, S, nmeas, ncon, grid, max_iter, max_order, budget, fit_tol, rel_improvement, patience,
        grid_points, final_points, dg, synth, out, t0, on_progress=None, as_given=None,
        real_scale: float = 1.0):
    """The iteration on ``P``; the best controller's final analysis on the loop of ``as_given``
    (default ``P``), the plant :func:`dgk_iteration` judges every try on."""
    if grid is None:
        grid = _default_dk_grid(P, grid_points)
    steps = _Steps(S, nmeas, ncon, grid, max_iter, fit_tol, budget, synth, on_progress)
    table = _Table(out, S, dg, real_scale)
    st = _DKState(fits=[None] * len(S))
    table.header()
    for it in range(1, max_iter + 1):
        if _iteration(steps, P, st, table, it, max_order, rel_improvement, patience, dg, real_scale):
            break
    _closer_to_optimum(steps, P, st, dg and bool(table.real_blocks))
    return _result(steps, P if as_given is None else as_given, st, final_points, dg, real_scale, out, t0,
                   new_loop=as_given is not None)


def _max_pole_real(CL) -> float:
    """The largest real part of the closed loop's poles (-inf without states)."""
    if not CL.nstates:
        return float("-inf")
    return float(np.linalg.eigvals(np.asarray(CL.A, float)).real.max())


#: back-off above the scaled plant's optimal level of the best loop's K step, redone at the end
_FINAL_BACKOFF = 1e-4


def _closer_to_optimum(steps: _Steps, P, st: _DKState, dg: bool) -> None:
    """The best loop's K step redone with the central controller 0.01 % above the scaled plant's
    optimal level (the iterations build it 0.1 % above, which keeps their path robust); the new
    loop replaces the best one if it is stable and its peak on the grid (the D-G bound with
    ``dg``) is lower.  The default synthesis only: a custom one is left as it is."""
    if steps.synth is not _k_step or st.best_plant is None:
        return
    mu0, _, _, fits, it = st.best
    steps.report(f"K-step of iteration {it} redone {100 * _FINAL_BACKOFF:g} % above the optimal level", 0.9)
    try:
        res = hinfsyn(st.best_plant, steps.nmeas, steps.ncon, backoff=_FINAL_BACKOFF, max_backoff=_FINAL_BACKOFF,
                      method="riccati")
    except (InfeasibleError, SolverError, IllPosedError, ModelError):
        return
    K = as_ss(res.K, "K")
    CL = lft_lower(P, K, steps.nmeas, steps.ncon)
    if _max_pole_real(CL) >= 0:
        return
    H = np.moveaxis(freqresp(CL, steps.grid), -1, 0)
    upper, _ = _sweep_upper(H, steps.Sc, st.Xd, progress=lambda f: steps.report(
        f"K-step of iteration {it} redone: mu-sweep, {100 * f:.0f} % converged", 0.9))
    mu = float(upper.max())
    if dg:
        mu = _dg_peak(H, steps.S, upper)[0]
    if mu < mu0:
        st.notes.append(f"iteration {it}'s K step redone {100 * _FINAL_BACKOFF:g} % above the scaled plant's "
                        f"optimal level (the iterations use 0.1 %): peak on the grid {mu0:.5f} -> {mu:.5f}")
        st.best = (mu, K, CL, fits, it)


def _result(steps: _Steps, P, st: _DKState, final_points, dg, real_scale, out, t0, new_loop: bool) -> DKResult:
    """The best loop of the run (with ``new_loop``, rebuilt on ``P``, the plant as given), its
    final analysis and the notes on near-axis poles."""
    S, grid, notes = steps.S, steps.grid, st.notes
    _, K, CL, used_fits, best_it = st.best
    if new_loop:
        CL = lft_lower(P, K, steps.nmeas, steps.ncon)
    near = near_axis_poles(P)
    max_re = _max_pole_real(CL)
    if near.size:
        notes.append(f"near-axis poles of the plant at {', '.join(f'{p.real:.3g}' for p in near)} rad/s: "
                     f"left out of the D-step grid (from {grid.min():.3g} rad/s), covered by the final "
                     f"analysis; the closed loop of the plant as given is "
                     f"{'stable' if max_re < 0 else 'NOT stable'} (largest pole real part {max_re:.3g})")
    final, low, low_c, mu_dg, _ = _final_analysis(
        CL, S, grid, final_points, dg,
        report=None if steps.on_progress is None else (lambda stage, f: steps.report(stage, 0.9 + 0.1 * f)))
    steps.report("final-analysis: done", 1.0)
    _print(out, f"best: iteration {best_it}, controller order {K.nstates}; fine grid: "
                f"{low:.4f} <= mu <= {final.peak_upper:.4f}"
                + (" (real parameters as complex)" if S.has_real else "")
                + (f", {mu_dg:.4f} with D-G scalings" if S.has_real and dg else ""))
    return DKResult(K=K, CL=CL, mu_upper=float(final.peak_upper), mu_upper_dg=mu_dg, mu_lower=low,
                    mu_lower_complex=low_c, peak_frequency=float(final.peak_frequency),
                    history=st.history, sweep=final, fits=used_fits, seconds=time.perf_counter() - t0,
                    best_iteration=best_it, notes=notes, near_axis_poles=near, max_pole_real=max_re,
                    real_scale=real_scale)
