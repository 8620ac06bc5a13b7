r"""The controller refined with the D-G scalings of every frequency (no fits).

How the grid follows the peaks (:func:`refine_controller`): it starts with the fine grid of
the final analysis of the controller given; each candidate step is also evaluated halfway
between its four largest local maxima and their neighbours (a probe above the old peak
rejects the step and joins the grid); every ``regrid_every`` accepted steps the grid is
refined around the ten largest local maxima (no new point closer than 0.001 % to one of the
grid, and a new point starts from the scalings of its nearest neighbour, which bound it from
above, so that only the points that could be the largest need scalings of their own); and
when the fine grid of the final analysis finds a peak the refinement grid missed (by more
than 0.01 %), its frequencies join the grid and the descent goes on for ``regrid_every`` more
steps (at most three times).
"""
from __future__ import annotations

import time

import numpy as np

from ..errors import ModelError
from ..lti import as_ss, blas_single_thread, freqresp, lft_lower
from ..mu import BlockStructure, default_grid
from ._dgstep import _dg_points, _refine_step
from ._dscale import _check_sizes
from ._loop import DKResult
from ._modal import _augmented_loop, _Modal
from ._report import _print
from ._sweep import _around_peaks, _default_dk_grid, _final_analysis, _local_maxima, near_axis_poles


def refine_controller(P, structure: BlockStructure, K, nmeas: int, ncon: int, *, omega=None,
                      max_steps: int = 60, time_limit: float | None = None, regrid_every: int = 15,
                      out=None, progress=None) -> DKResult:
    r"""Lower the D-G bound of a loop by moving its controller, with the scalings of every frequency.

    The K step of D-K iteration needs rational scalings, and with real
    parameters their G scalings are the obstacle (see :func:`dgk_iteration`).
    Here the controller itself is the unknown and the scalings are never
    fitted: at each frequency of a grid, the D-G upper bound of the loop
    :math:`M = \mathcal F_\ell(P, K)` is :math:`\beta^2 = \lambda_{\max}(Q)`,

    .. math::

        Q = D_r^{-1/2}\big(M^H D_\ell M + j(GM - M^HG^H)\big)D_r^{-1/2},

    with the scalings :math:`D_\ell, D_r, G` optimal for the current
    controller (``mutext.mu.mu_upper(method="fast")``, the LMI where the fast
    scalings do not reproduce their value).  With the scalings held, the peak
    of :math:`\lambda_{\max}(Q)` over the grid is a function of the
    controller's parameters (its real modal form: the modes, ``B``, ``C``,
    ``D``; the order stays).  Its linearisation on the top eigenspace of each
    frequency near the peak, :math:`dM = U\,dK\,V` with :math:`U, V` the
    closed-loop maps from the control input to ``z`` and from ``w`` to the
    measurement, gives a small semidefinite program for the step, inside a
    trust region (each parameter and :math:`K(j\omega)` at every frequency
    move at most a fraction :math:`\rho` of their size).  A step counts only
    if the loop stays stable and the D-G bound recomputed for the new
    controller (new scalings where the old ones could decide the peak) falls:
    the result is never worse than the controller given (the two are also
    compared on the fine grid of the final analysis, and the controller given
    is returned if it is lower there).  A step can push a narrow peak up
    between grid points, so the grid follows the peaks: it starts with the
    fine grid of the controller given, probes between the largest local maxima
    can reject a step (and join the grid), the largest maxima are refined every
    ``regrid_every`` accepted steps, and a peak the final analysis finds off
    the grid joins it (the rules in detail: :mod:`mutext.dk._refine`).

    This is a local descent on a non-smooth function (the peak over
    frequencies and over eigenvalues), in the spirit of the non-smooth
    mu-synthesis of Apkarian and Noll [AN]_: progress is fast, then slow, and
    it depends on the path.  On the two-mass problem at 0.041 m, the 20-state
    D-G-K controller's 1.0131 falls to 0.9896 in 100 steps (13 s), 0.9893 in
    1,000 (2.5 min), 0.9889 in 2,000 and 0.9875 in 5,000 (15 min), then
    faster, to 0.9794 in 8,775 (40 min): a step takes a tenth to half a second
    (as the grid grows around the peaks), and most gain very little each.  With complex blocks only, ``G = 0`` and
    the scalings are D-K's D scalings, held instead of fitted: on the
    distillation column (:mod:`mutext.examples.distillation`) 80 steps take
    the D-K controller of coarse fits (``fit_tol=0.02``) from 1.0501 to 0.9943, with the same 18 states.

    Parameters
    ----------
    P, structure, nmeas, ncon
        As for :func:`dk_iteration`.
    K : control.StateSpace
        A stabilising controller, e.g. ``dgk_iteration(...).K``; its poles must be
        simple enough for a real modal form (eigenvector condition number up to 1e10).
    omega : array_like, optional
        Starting grid (default: the grid of the final analysis of
        :func:`dk_iteration`, 200 points 1.5 decades beyond the loop's poles,
        plus the D-step grid).  Frequencies within 0.1 % of a lightly damped
        pole of ``P`` are left out (the loop is computed from its own
        realisation, so this only avoids ill-conditioned points).
    max_steps : int
        Model steps (accepted or not) before the fine grid is checked; each
        time it finds a peak the refinement grid missed (at most three times),
        ``regrid_every`` more follow.
    time_limit : float, optional
        Seconds after which no new step is started.
    regrid_every : int
        Accepted steps between grid refinements, and the steps added after a
        missed peak.
    out : file or None
        Where to print one line per step.
    progress : callable, optional
        ``progress(stage, fraction)`` once per step (the controller given's
        analysis takes 0-0.05 of the bar, the steps 0.05-0.93, the final
        analysis the rest).

    Returns
    -------
    DKResult
        ``K`` the refined controller (same order), ``CL``, ``mu_upper_dg``,
        ``mu_lower`` and the other bounds from the same final analysis as
        :func:`dk_iteration` (a fine grid independent of the refinement grid),
        ``history`` one row per step (``step``, ``mu_dg`` on the refinement
        grid, ``model`` the model's prediction, ``rho``, ``accepted``,
        ``grid_points``, ``seconds``, ``round``: 0, then 1, 2, 3 after each
        missed peak, whose frequencies can raise ``mu_dg``).

    Raises
    ------
    ModelError
        Sizes that do not match, a controller that does not stabilise ``P``,
        a controller without a usable modal form, bad options.

    References
    ----------
    .. [AN] P. Apkarian and D. Noll, "Nonsmooth H-infinity synthesis", *IEEE
       Trans. Automatic Control* 51 (2006) 71-86.

    Examples
    --------
    Two steps on the first D-K controller (the H-infinity one, 6 states) of the distillation
    column, whose blocks are complex (no G scalings; about 2 s, most of it the analyses of the
    fine grid before and after): the peak falls from 1.181 to 1.180, the order stays.

    >>> from mutext.dk import dk_iteration
    >>> from mutext.examples import distillation
    >>> P, S = distillation.plant(), distillation.structure()
    >>> dkr = dk_iteration(P, S, 2, 2, max_iter=1, grid_points=12, final_points=12)
    >>> ref = refine_controller(P, S, dkr.K, 2, 2, max_steps=2)
    >>> bool(ref.mu_upper_dg < dkr.mu_upper_dg), ref.K.nstates == dkr.K.nstates
    (True, True)
    """
    t0 = time.perf_counter()
    P, S, K, CL0 = _refine_arguments(P, structure, K, nmeas, ncon, max_steps, regrid_every, time_limit)
    given, d = _start(_Problem(P, S, K, nmeas, ncon, progress), K, CL0, omega)
    start = d.peak()
    _print(out, f"{'step':>4} {'mu D-G (grid)':>14} {'model':>9} {'rho':>9} {'':>8} {'grid':>5} {'seconds':>8}")
    checked = _descend(d, max_steps, time_limit, regrid_every, out, t0)
    return _refined_result(d, K, given, checked, start, out, t0)


def _start(prob, K, CL0, omega):
    """The controller given, its loop and final analysis, and the descent from it."""
    w = prob.start_grid(CL0, omega)
    # the controller given, on the fine grid of the final analysis: its frequencies join the
    # refinement grid (they hold the fine points around its peaks), and the result is compared
    # with it on that same grid at the end, so that it is never worse there
    given = prob.analysed(K, (0.0, 0.05))
    fin_g = given[1]
    w = prob.usable(np.unique(np.concatenate([w, fin_g[0].omega, fin_g[4]])))
    return given, _Descent(prob, prob.modal.theta.copy(), w)


def _refine_arguments(P, structure, K, nmeas, ncon, max_steps, regrid_every, time_limit):
    """Checked arguments of :func:`refine_controller`: the plant, the structure, the controller
    and the loop of the two, which must be stable."""
    P = as_ss(P, "P")
    if not isinstance(structure, BlockStructure):
        raise ModelError(f"structure must be a BlockStructure, got {type(structure).__name__}")
    S = structure
    _check_sizes(P, S, nmeas, ncon)
    K = as_ss(K, "K")
    if K.ninputs != nmeas or K.noutputs != ncon:
        raise ModelError(f"K has {K.ninputs} inputs and {K.noutputs} outputs, but nmeas={nmeas}, ncon={ncon}")
    for name, v, least in (("max_steps", max_steps, 1), ("regrid_every", regrid_every, 1)):
        if isinstance(v, (bool, np.bool_)) or not (isinstance(v, (int, np.integer)) and v >= least):
            raise ModelError(f"{name} must be an integer >= {least}, got {v!r}")
    if time_limit is not None and not (isinstance(time_limit, (int, float, np.integer, np.floating))
                                       and not isinstance(time_limit, bool) and time_limit > 0):
        raise ModelError(f"time_limit must be a positive number of seconds or None, got {time_limit!r}")
    CL0 = lft_lower(P, K, nmeas, ncon)
    cl_poles = np.linalg.eigvals(np.asarray(CL0.A, float)) if CL0.nstates else np.zeros(0)
    if cl_poles.size and cl_poles.real.max() >= 0:
        raise ModelError(f"K does not stabilise P (closed-loop pole with real part {cl_poles.real.max():.3g})")
    return P, S, K, CL0


class _Problem:
    """The loop of ``P`` and a controller of the real modal form of ``K`` (``modal``): its
    response and D-G scalings at given parameters and frequencies, the grid's rules and the
    final analysis."""

    def __init__(self, P, S, K, nmeas, ncon, progress):
        self.P, self.S, self.nmeas, self.ncon, self.progress = P, S, nmeas, ncon, progress
        self.nc, self.nr = S.ncols, S.nrows
        self.modal = _Modal(K)
        self.light = np.zeros(0)

    def start_grid(self, CL0, omega):
        """The starting grid (see :func:`refine_controller`); also records the lightly damped
        poles of ``P`` whose frequencies every grid leaves out."""
        P = self.P
        if omega is None:
            w = np.unique(np.concatenate([default_grid(CL0, n=200, decades=1.5), _default_dk_grid(P, 80)]))
        else:
            w = np.unique(np.asarray(omega, float).ravel())
            if w.size == 0 or not (np.all(np.isfinite(w)) and np.all(w > 0)):
                raise ModelError("the frequency grid omega must hold positive, finite frequencies (rad/s)")
        ppoles = np.linalg.eigvals(np.asarray(P.A, float)) if P.nstates else np.zeros(0)
        self.light = np.abs(ppoles[np.abs(ppoles.real) < 1e-3 * np.abs(ppoles)].imag)
        return w

    def usable(self, w):
        """The frequencies of ``w`` not within 0.1 % of a lightly damped pole of ``P``."""
        light = self.light
        return w[np.min(np.abs(w[:, None] - light[None, :]), axis=1) > 1e-3 * w] if light.size else w

    def new_points(self, wn, w):
        """The frequencies ``wn`` not within 0.001 % of a grid point: on a flat stretch of the
        bound, every point is a local maximum by a few digits, and probes between ever closer
        points would grow the grid (and the cost of a step) without finding anything."""
        wn = self.usable(np.setdiff1d(np.unique(wn), w))
        if not wn.size or w.size < 2:
            return wn
        lw = np.log(w)
        i = np.clip(np.searchsorted(lw, np.log(wn)), 1, lw.size - 1)
        gap = np.minimum(np.abs(np.log(wn) - lw[i - 1]), np.abs(np.log(wn) - lw[i]))
        return wn[gap > 1e-5]

    def evaluate(self, theta, w):
        """Whether the loop with parameters ``theta`` is stable, and its blocks M, U, V on ``w``."""
        nc, nr = self.nc, self.nr
        Kt = self.modal.ss(theta)
        CLa = _augmented_loop(self.P, Kt, nc, nr, self.nmeas, self.ncon)
        poles = np.linalg.eigvals(np.asarray(CLa.A, float)) if CLa.nstates else np.zeros(0)
        stable = not poles.size or poles.real.max() < 0
        F = np.moveaxis(freqresp(CLa, w), -1, 0)
        return stable, F[:, :nc, :nr], F[:, :nc, nr:], F[:, nc:, :nr]

    def at(self, th, wp, near=None):
        """(M, U, V, scalings) of the loop with parameters ``th`` at the frequencies ``wp``.
        With ``near`` (a grid and its scalings), each frequency starts from the scalings of
        the nearest grid point, whose values bound it from above, and only those that could
        be the largest get their own (as in :func:`_dg_points`): a probe then costs one
        eigenvalue problem instead of a descent, and no value exceeds the largest exact one."""
        _, Mp, Up, Vp = self.evaluate(th, wp)
        if near is None or not wp.size:
            return Mp, Up, Vp, _dg_points(Mp, self.S)
        wg, pg = near
        j = np.abs(np.log(wp)[:, None] - np.log(wg)[None, :]).argmin(axis=1)
        return Mp, Up, Vp, _dg_points(Mp, self.S, [pg[k] for k in j])

    def probes(self, w, pts):
        """Frequencies halfway (in log) between the largest local maxima and their neighbours."""
        idx = _local_maxima([p.value for p in pts], 4)
        wp = [np.sqrt(w[i] * w[j]) for i in idx for j in (i - 1, i + 1) if 0 <= j < w.size]
        return self.new_points(np.asarray(wp), w) if wp else np.zeros(0)

    def analysed(self, Kx, part):
        """The loop with the controller ``Kx`` and its final analysis (:func:`_final_analysis`),
        reported on the part ``part`` (from, to) of the progress bar."""
        progress = self.progress
        CLx = lft_lower(self.P, Kx, self.nmeas, self.ncon)
        rep = None if progress is None else (lambda stage, f: progress(stage, part[0] + (part[1] - part[0]) * f))
        return CLx, _final_analysis(CLx, self.S, _default_dk_grid(self.P, 80), 200, True, report=rep)


def _merge(w, data, wp, extra):
    """The grid and its data with the frequencies ``wp`` and their data added, in order."""
    order = np.argsort(np.concatenate([w, wp]))
    M, U, V, pts = data
    Mp, Up, Vp, pp = extra
    out = [np.concatenate([a, b])[order] for a, b in ((w, wp), (M, Mp), (U, Up), (V, Vp))]
    allpts = list(pts) + list(pp)
    return out[0], out[1], out[2], out[3], [allpts[i] for i in order]


class _Descent:
    """The refinement's state: the controller's parameters ``theta``, the grid ``w`` with the
    loop's blocks ``M, U, V`` and the scalings ``pts`` on it, the trust region ``rho``, the
    steps taken and accepted, the history and the notes."""

    def __init__(self, prob: _Problem, theta, w):
        self.prob, self.theta = prob, theta
        self.set_grid(w)
        self.history, self.notes = [], []
        self.rho, self.accepted, self.step, self.timed_out = 1e-3, 0, 0, False
        self.round = 0                  # 0, then 1, 2, 3 after each peak the fine grid found

    def set_grid(self, w):
        """A new grid, with the loop's data and scalings computed afresh on it."""
        self.w = w
        self.M, self.U, self.V, self.pts = self.prob.at(self.theta, w)

    def peak(self) -> float:
        return max(p.value for p in self.pts)

    def add(self, wp, extra):
        """The frequencies ``wp`` and their data ``extra`` = (M, U, V, scalings) join the grid."""
        self.w, self.M, self.U, self.V, self.pts = _merge(self.w, (self.M, self.U, self.V, self.pts), wp, extra)

    def trial(self):
        """One model step (:func:`_refine_step`), kept if the D-G bound on the grid falls and no
        probe between its largest maxima rises to the old peak.  Returns (accepted, missed: a
        probe found the peak the grid missed, the model's predicted bound)."""
        prob, theta, w, pts = self.prob, self.theta, self.w, self.pts
        peak = self.peak()
        res = _refine_step(prob.modal, theta, pts, self.M, self.U, self.V, self.rho, w)
        if res is None:
            return False, False, float("nan")
        dstep, tau, lam_peak = res
        model = float(np.sqrt(max(tau, 0.0)))
        pred = lam_peak - tau
        if not pred > 1e-12 * lam_peak:
            return False, False, model
        cand = theta + prob.modal.scale * dstep
        st, Mn, Un, Vn = prob.evaluate(cand, w)
        if not st:
            return False, False, model
        new = _dg_points(Mn, prob.S, pts, reject_at=peak * (1.0 - 1e-9))
        vn = np.inf if new is None else max(p.value for p in new)
        if not vn < peak * (1.0 - 1e-9):
            return False, False, model
        # a step may push a narrow peak up between grid points: probe
        # between the largest local maxima and their neighbours
        wp = prob.probes(w, new)
        probed = prob.at(cand, wp, (w, new)) if wp.size else None
        if probed and max(p.value for p in probed[3]) >= peak * (1.0 - 1e-9):
            # rejected, and the grid keeps the probes (with this loop's data)
            self.add(wp, prob.at(theta, wp, (w, pts)))
            return False, True, model
        ratio = (peak ** 2 - vn ** 2) / pred
        self.theta, self.M, self.U, self.V, self.pts = cand, Mn, Un, Vn, new
        if probed:
            # the grid keeps the probes near the new peak
            near = np.flatnonzero([p.value >= 0.98 * vn for p in probed[3]])
            if near.size:
                self.add(wp[near], tuple(x[near] for x in probed[:3]) + ([probed[3][i] for i in near],))
        rho = self.rho
        self.rho = min(2.0 * rho, 0.2) if ratio > 0.5 else (rho / 2.0 if ratio < 0.1 else rho)
        return True, False, model

    def run(self, limit, max_steps, time_limit, t0, regrid_every, out):
        """Model steps up to step ``limit``, the time limit or a trust region too small to move;
        every ``regrid_every`` accepted steps the grid is refined around its largest maxima."""
        prob = self.prob
        while self.step < limit:
            if time_limit is not None and time.perf_counter() - t0 > time_limit:
                self.notes.append(f"refine: time limit of {time_limit:g} s reached after {self.step} steps")
                self.timed_out = True
                break
            self.step += 1
            step = self.step
            if prob.progress is not None:
                prob.progress(f"refine step {step}/{limit}: mu D-G {self.peak():.5f}, "
                              f"{self.w.size} frequencies", 0.05 + 0.88 * min(step - 1, max_steps) / max_steps)
            ti = time.perf_counter()
            ok, missed, model = self.trial()
            if not ok:
                self.rho /= 2.0 if missed else 4.0
            else:
                self.accepted += 1
            mu_now = self.peak()
            self.history.append({"step": step, "mu_dg": mu_now, "model": model, "rho": self.rho, "accepted": ok,
                                 "grid_points": int(self.w.size), "seconds": time.perf_counter() - ti,
                                 "round": self.round})
            _print(out, f"{step:>4} {mu_now:>14.6f} {model:>9.5f} {self.rho:>9.2e} "
                        f"{'accepted' if ok else 'rejected':>8} {self.w.size:>5} {time.perf_counter() - ti:>8.2f}")
            if ok and self.accepted % regrid_every == 0:
                extra = _around_peaks(self.w, np.array([p.value for p in self.pts]), 10, 6)
                wn = prob.new_points(np.concatenate(extra), self.w) if extra else np.zeros(0)
                if wn.size:
                    self.add(wn, prob.at(self.theta, wn, (self.w, self.pts)))
            if self.rho < 1e-7:
                self.notes.append(f"refine: stopped at step {step}, no model step lowers the bound "
                                  f"(trust region {self.rho:.1e})")
                break


def _descend(d: _Descent, max_steps, time_limit, regrid_every, out, t0):
    """Rounds of model steps, each ended by the fine grid of the final analysis; while that
    finds a peak the refinement grid missed (at most three times), its frequencies join the
    grid and ``regrid_every`` more steps follow.  Returns the loop with the lowest bound on its
    fine grid among the checks (a later round, on a grid with the peak it missed, can end higher
    than an earlier one), its analysis and its round."""
    prob, limit, best = d.prob, max_steps, None
    for check in range(4):
        d.round = check
        with blas_single_thread():
            d.run(limit, max_steps, time_limit, t0, regrid_every, out)
        Kr = prob.modal.ss(d.theta)
        f = 0.05 + 0.88 * min(d.step, max_steps) / max_steps     # the bar holds while the fine grid is checked
        CL, (final, low, low_c, mu_dg, extra) = prob.analysed(Kr, (f, f))
        if best is None or mu_dg < best[2][3]:
            best = (Kr, CL, (final, low, low_c, mu_dg, extra), check)
        on_grid = d.peak()
        if d.timed_out or check == 3 or mu_dg <= on_grid * (1.0 + 1e-4):
            break
        # the fine grid found a peak the refinement grid missed by more than 0.01 % (a step
        # raised the bound between its points, or beyond its ends): its frequencies join the
        # grid and the descent goes on for ``regrid_every`` more steps, from a trust region
        # that can still move
        d.notes.append(f"refine: after step {d.step} the fine grid found {mu_dg:.5f} where the refinement grid "
                       f"had {on_grid:.5f}; its {final.omega.size} frequencies were added and up to "
                       f"{regrid_every} more steps follow")
        d.set_grid(prob.usable(np.unique(np.concatenate([d.w, final.omega, extra]))))
        d.rho, limit = max(d.rho, 1e-4), d.step + regrid_every
    return best


def _refined_result(d: _Descent, K, given, checked, start, out, t0) -> DKResult:
    """The refined controller, or the one given if the final grid does not find it lower."""
    notes, P = d.notes, d.prob.P
    Kr, CL, (final, low, low_c, mu_dg, _), kept = checked
    CLg, fin_g = given
    if kept < d.round:
        notes.append(f"refine: the loop at the end of round {kept} is returned: on its fine grid it is lower "
                     f"({mu_dg:.5f}) than the later rounds' loops")
    if d.accepted and fin_g[3] < mu_dg:
        notes.append(f"refine: on the final grid the refined loop ({mu_dg:.5f}) is not below the loop "
                     f"given ({fin_g[3]:.5f}): the controller given is returned")
        Kr, CL, (final, low, low_c, mu_dg, _) = K, CLg, fin_g
    cl_poles = np.linalg.eigvals(np.asarray(CL.A, float)) if CL.nstates else np.zeros(0)
    max_re = float(cl_poles.real.max()) if cl_poles.size else float("-inf")
    notes.append(f"refine: {d.accepted} of {len(d.history)} steps accepted; D-G bound on the refinement grid "
                 f"{start:.5f} -> {d.peak():.5f}, on the final grid {mu_dg:.5f}")
    _print(out, f"refined: fine grid: {low:.4f} <= mu <= {mu_dg:.4f} (D-G), {final.peak_upper:.4f} complex; "
                f"controller order {Kr.nstates}; {time.perf_counter() - t0:.1f} s")
    return DKResult(K=Kr, CL=CL, mu_upper=float(final.peak_upper), mu_upper_dg=mu_dg, mu_lower=low,
                    mu_lower_complex=low_c, peak_frequency=float(final.peak_frequency), history=d.history,
                    sweep=final, fits=[], seconds=time.perf_counter() - t0, best_iteration=0, notes=notes,
                    near_axis_poles=near_axis_poles(P), max_pole_real=max_re)
