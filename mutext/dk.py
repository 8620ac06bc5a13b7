r"""Mu-synthesis by D-K iteration.

For a generalized plant ``P`` whose first inputs/outputs are the channels of
a block structure :math:`\boldsymbol\Delta` (uncertainty and performance
blocks) and whose last are the measurements ``y`` and controls ``u``, D-K
iteration alternates two steps on the upper bound

.. math::
    \min_K \sup_\omega \inf_{D\in\mathcal D}
    \bar\sigma\big(D(j\omega)\,\mathcal F_\ell(P, K)(j\omega)\,D(j\omega)^{-1}\big)

([ZDG]_ sec. 11.5; [SP]_ sec. 8.12; Doyle's original scheme):

* **K step**: with rational, stable, minimum-phase scalings :math:`\hat D(s)`
  fixed, an H-infinity controller for :math:`\hat D P \hat D^{-1}` by
  :func:`mutext.hinf.hinfsyn` (0.1 % above the optimal level; slycot's
  Riccati synthesis, verified, if the LMI controller fails; then once more
  with lower-order scalings);
* **D step**: the optimal diagonal scalings :math:`D(\omega)` of the new
  closed loop on a frequency grid, each block's fitted by a stable,
  minimum-phase, biproper transfer function of order 0-5.

The pointwise scalings minimise the convex :math:`\log\bar\sigma(e^XMe^{-X})`
(one log scaling per block, the last fixed to 0) by the same
Osborne-plus-ellipsoid method as ``mutext.mu.mu_upper(method="osborne")``,
run on all frequencies at once and warm-started from the previous iteration.

What the fit must achieve is not closeness to the pointwise optimum but a
scaled closed loop whose peak stays near the peak of :math:`\mu`: far from the
peak the bound has slack and many scalings are equally good.  For every block
and frequency the D step therefore computes the interval of
:math:`\log d_k` over which :math:`\bar\sigma(DMD^{-1})` stays below
:math:`(1 + \text{fit\_tol})\,\max_\omega\mu` (a convex function of
:math:`\log d_k`, so the interval is found by bisection), and fits the middle of
that interval, weighted by the inverse of its half width.  Orders are raised
one at a time for the worst-fitted block until every fit stays inside half its
interval or a budget of added states is spent (the LMI K step slows down
steeply with the plant order); frequencies where the fitted scalings together
still exceed the level get narrower intervals and the fit is repeated.

The fit (:func:`fit_dscale`) works on :math:`\Phi(x) = |D(j\omega)|^2`,
:math:`x = \omega^2`, a positive rational function of :math:`x`.  Its poles
(real, or complex pairs for resonant scalings) are located by vector fitting (a
sequence of linear least-squares problems, Gustavsen and Semlyen [GS]_) and its
residues by a convex quadratic program with :math:`\Phi \ge 0` imposed on a
dense grid; a spectral factorisation then gives :math:`\hat D(s)` with all
poles and zeros in the left half plane.

Real parameters are treated as complex scalars in the iteration (D scalings
only, as in the classical ``dksyn``).  :func:`dgk_iteration` keeps them real
where it counts: it runs this iteration with the real parameters' ranges
scaled by a factor :math:`c \le 1` in the K steps and picks :math:`c` by the
D-G bound of the loop of the plant as given (see its docstring for the
approximation).  On the two-mass problem at 0.041 m it lowers the D-G bound
from 1.0187 to 1.0148 with the same 16-state controller budget.  A full D-G-K
iteration (``musyn``; Young 1996) would fit a G scaling per parameter and
frequency: for ``1 x 1`` real blocks these are discs
(:func:`mutext.mu.dg_disc` turns the D-G bound into the equivalent complex
problem, the disc centres :math:`jb_k(\omega)/\beta` closed as a feedback
around the real channels), and a K step needs stable rational filters for
them.  :math:`b_k` is odd in :math:`\omega` (so :math:`jb_k` acts like a
differentiator, and a stable filter adds a real part that widens the disc)
and not unique away from the peak.  Prototypes of that kind on the two-mass
problem (fitted centre filters; the pointwise "mu-K" shrinkage of the real
channels; Young's affine form with para-skew G filters made causal by an
all-pass, exact on the axis) gave D-G bounds of 1.02-1.49 (the book's mu
chapter has the details).  :func:`refine_controller` avoids the filters: it
keeps the optimal D-G scalings of every frequency and moves the controller's
parameters instead (trust-region steps on the peak of the scaled bound, each
checked on the recomputed D-G bound); 300 steps take the D-G-K controller
with 20 states from 1.0131 to 0.9896 (AB13MD; the thesis: 0.989).

After the iteration the best closed loop is analysed
with the optimal, unfitted scalings on a fine grid whose peaks are refined
(every value is :math:`\bar\sigma(DMD^{-1})` for an explicit :math:`D`, a
certified bound at that frequency), with lower bounds at the peaks
(:func:`mutext.mu.mu_sweep`) and, when the structure has real blocks, the
D-G bound at the frequencies that decide its peak
(:func:`mutext.mu.mu_upper`, ``method="fast"``).

Weights with integrators or near-axis poles.  A performance weight that
approximates an integrator by a pole very close to the axis (Skogestad and
Postlethwaite's distillation column: :math:`W_P` with poles at -1e-6 rad/s)
puts into the generalized plant states that the measurements do not see: they
stay poles of every closed loop, so the loop is stable only if they are stable
(an exact integrator, a pole at 0, cannot be handled: move it to a small
negative value first), and :math:`\mu` at frequencies below them is set by the
controller's gain there.  The iteration treats them as follows, with nothing
shifted, so that every reported number is for the plant as given:

* the K step works on the plant as given (:func:`mutext.hinf.hinfsyn`: the
  Riccati central controller copes with the stiff Lyapunov and Riccati
  equations; an LMI-only K step could not, and its error names the poles);
* the D steps' default grid leaves out poles that lie three decades or more
  below the rest of the plant's poles (:func:`near_axis_poles`; the grid spans
  1.5 decades beyond the other poles): fitting scalings over eleven decades
  costs fit accuracy where the peak of :math:`\mu` is (on the distillation
  column, 1.064 against 1.052 after the same iterations);
* the final analysis grid does reach 1.5 decades below them, so a peak of
  :math:`\mu` at low frequency is not missed; ``DKResult.near_axis_poles``
  lists them, ``DKResult.max_pole_real`` is the largest real part of the
  closed-loop poles of the plant as given, and a note records both.

The scalings converge slowly on this problem (about 0.2 % per iteration):
``fit_tol=5e-4, rel_improvement=1e-3, max_iter=20`` reaches 1.029 with an
18-state controller in a few seconds, where the defaults stop at 1.052.

References
----------
.. [ZDG] K. Zhou, J. C. Doyle and K. Glover, *Robust and Optimal Control*,
   Prentice Hall, 1996, ch. 11.
.. [SP] S. Skogestad and I. Postlethwaite, *Multivariable Feedback Control*,
   2nd ed., Wiley, 2005, sec. 8.12.
.. [GS] B. Gustavsen and A. Semlyen, "Rational approximation of frequency
   domain responses by vector fitting", *IEEE Trans. Power Delivery* 14
   (1999) 1052-1061.
"""
from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field

import control as ct
import numpy as np
from scipy.linalg import cdf2rdf

from .errors import IllPosedError, InfeasibleError, ModelError, SolverError
from .frfit import MagnitudeFit, _constant, fit_magnitude
from .hinf import hinfsyn, slycot_hinfsyn
from .lti import as_ss, blas_single_thread, freqresp, lft_lower, ss
from .mu import BlockStructure, BranchPeak, MuSweep, branch_peak, default_grid, mu_sweep, mu_upper

__all__ = ["DScaleFit", "fit_dscale", "fit_dscale_auto", "scaled_plant", "DKResult", "dk_iteration",
           "dgk_iteration", "real_scaled_plant", "refine_controller", "near_axis_poles", "branch_mu"]




# ----------------------------------------------------------------------------
# D-scale fitting
# ----------------------------------------------------------------------------

#: the fitted D scaling of one block (:func:`mutext.frfit.fit_magnitude`)
DScaleFit = MagnitudeFit


def fit_dscale(omega, mag, order: int, weight=None, iterations: int = 8) -> DScaleFit:
    r"""Fit :math:`|\hat D(j\omega)| \approx` ``mag`` by a stable, minimum-phase, biproper :math:`\hat D`.

    The vector fit of :func:`mutext.frfit.fit_magnitude` (same parameters,
    result and errors), on :math:`|\hat D|^2` as a rational function of
    :math:`\omega^2`, made stable and minimum phase by spectral factorisation.
    """
    return fit_magnitude(omega, mag, order, weight=weight, iterations=iterations)


def fit_dscale_auto(omega, mag, weight=None, max_order: int = 4, tol: float = 0.05) -> DScaleFit:
    """Lowest order (0..``max_order``) whose weighted log-magnitude error is at most ``tol``.

    If no order reaches ``tol``, the most accurate fit is returned; a higher
    order is preferred only if it lowers the error by at least 20 %.
    """
    best = None
    for n in range(0, max_order + 1):
        try:
            f = fit_dscale(omega, mag, n, weight)
        except (SolverError, np.linalg.LinAlgError):
            continue
        if best is None or f.error < best.error * 0.8:
            best = f
        if f.error <= tol:
            return f
    if best is None:
        raise SolverError("D-scale fit failed at every order")
    return best


# ----------------------------------------------------------------------------
# scaled plant
# ----------------------------------------------------------------------------

def _append(systems):
    out = systems[0]
    for s in systems[1:]:
        out = ct.append(out, s)
    return out


def _check_sizes(P, structure: BlockStructure, nmeas: int, ncon: int):
    for name, v in (("nmeas", nmeas), ("ncon", ncon)):
        if not isinstance(v, (int, np.integer)) or v < 1:
            raise ModelError(f"{name} must be a positive integer, got {v!r}")
    if P.ninputs != structure.nrows + ncon or P.noutputs != structure.ncols + nmeas:
        raise ModelError(
            f"size mismatch: the plant has {P.ninputs} inputs and {P.noutputs} outputs, but the "
            f"block structure {structure!r} has {structure.nrows} input and {structure.ncols} output "
            f"channels, which with ncon={ncon} and nmeas={nmeas} needs {structure.nrows + ncon} "
            f"inputs and {structure.ncols + nmeas} outputs")


def scaled_plant(P, structure: BlockStructure, fits, nmeas: int, ncon: int) -> ct.StateSpace:
    r"""The D-scaled plant :math:`\operatorname{diag}(\hat D_\ell, I)\,P\,\operatorname{diag}(\hat D_r^{-1}, I)`.

    Parameters
    ----------
    P : control.StateSpace
        Generalized plant with inputs ``[w_Delta; u]`` and outputs ``[z_Delta; y]``.
    structure : BlockStructure
    fits : sequence
        One :class:`DScaleFit` (or ``None`` for :math:`D = 1`) per block;
        block ``k`` of size ``rows x cols`` gets :math:`\hat D_k I_{cols}` on its
        ``z`` outputs and :math:`\hat D_k^{-1} I_{rows}` on its ``w`` inputs.
    nmeas, ncon : int

    Returns
    -------
    control.StateSpace
        Same inputs and outputs as ``P``; order ``P.nstates`` plus, per block,
        ``(rows + cols)`` times the fit order.
    """
    P = as_ss(P)
    _check_sizes(P, structure, nmeas, ncon)
    if len(fits) != len(structure):
        raise ModelError(f"need one D-scale per block ({len(structure)}), got {len(fits)}")
    one = _constant(1.0)
    left, right = [], []
    for b, f in zip(structure.blocks, fits):
        trivial = f is None or (f.order == 0 and f.gain == 1.0)
        left += [one if trivial else f.sys] * b.cols
        right += [one if trivial else f.inverse()] * b.rows
    left += [one] * nmeas
    right += [one] * ncon
    out = ct.series(_append(right), P, _append(left))
    return ss(out.A, out.B, out.C, out.D, inputs=P.input_labels, outputs=P.output_labels)


# ----------------------------------------------------------------------------
# D step
# ----------------------------------------------------------------------------

def _scaled_norms(H, S: BlockStructure, X) -> np.ndarray:
    """sigma_max(D M D^-1) at each frequency; ``H`` is (nw, ncols, nrows), ``X`` the log
    scalings (nw, nblocks)."""
    A = np.exp(X[:, S.col_block])[:, :, None] * H * np.exp(-X[:, S.row_block])[:, None, :]
    return np.linalg.norm(A, 2, axis=(1, 2))


def _norms_and_grads(H, S: BlockStructure, X):
    """sigma_max(D M D^-1) and its log-derivatives in log d (one column per block)."""
    A = np.exp(X[:, S.col_block])[:, :, None] * H * np.exp(-X[:, S.row_block])[:, None, :]
    U, s, Vh = np.linalg.svd(A)
    m = X.shape[1]
    El = np.eye(m)[S.col_block]            # (ncols, m): z entry -> block
    Er = np.eye(m)[S.row_block]            # (nrows, m): w entry -> block
    g = np.abs(U[:, :, 0]) ** 2 @ El - np.abs(Vh[:, 0, :]) ** 2 @ Er
    return s[:, 0], g


def _sweep_upper(H, S: BlockStructure, X0=None, tol: float = 1e-6, max_iter: int = 2000,
                 radius: float = 8.0, progress=None):
    r"""Diagonal-D upper bound of mu at every frequency at once.

    The same problem as ``mu_upper(method="osborne")`` (minimise the convex
    :math:`\log\bar\sigma(e^XMe^{-X})` over one log scaling per block, the last
    fixed to 0) by a central-cut ellipsoid method run on all frequencies in
    parallel (one batched SVD per step), started from ``X0`` (the previous
    iteration's scalings) or from Osborne balancing.  Each value is
    :math:`\bar\sigma(DMD^{-1})` for the returned :math:`D`, so a valid bound.

    ``progress(fraction)``, if given, is called every 50 steps with the
    fraction of frequencies converged.

    Returns
    -------
    upper : (nw,) ndarray
    X : (nw, nblocks) ndarray
        Log scalings, last column 0.
    """
    nw = H.shape[0]
    m = len(S)
    if X0 is None:
        # Osborne balancing of the block-norm matrices (off-diagonal blocks
        # only; the floor keeps blocks that are zero from driving d to 0 or inf)
        Bn = np.empty((nw, m, m))
        for i in range(m):
            for j in range(m):
                Bn[:, i, j] = np.linalg.norm(H[:, S.col_slices[i], S.row_slices[j]], axis=(1, 2))
        floor = 1e-100 + 1e-12 * Bn.max(axis=(1, 2), keepdims=True)
        Bn[:, np.arange(m), np.arange(m)] = 0.0
        Bn += floor
        X0 = np.zeros((nw, m))
        for _ in range(30 if m > 1 else 0):
            for i in range(m):
                e = np.exp(X0)
                r = np.sqrt(np.sum((Bn[:, i, :] / e) ** 2, axis=1))
                c = np.sqrt(np.sum((Bn[:, :, i] * e) ** 2, axis=1))
                X0[:, i] = 0.5 * (np.log(c) - np.log(r))
    X0 = np.asarray(X0, float) - np.asarray(X0, float)[:, -1:]
    s, _ = _norms_and_grads(H, S, X0)
    best_f = np.log(np.maximum(s, 1e-300))
    best_X = X0.copy()
    n = m - 1
    if n == 0:
        return s, best_X
    X = X0.copy()
    P = np.repeat((radius ** 2 * np.eye(n))[None], nw, axis=0)
    lower = np.full(nw, -np.inf)
    active = np.ones(nw, bool)
    for step in range(max_iter):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        if progress is not None and step % 50 == 0:
            progress(1.0 - idx.size / nw)
        s, g = _norms_and_grads(H[idx], S, X[idx])
        f = np.log(np.maximum(s, 1e-300))
        better = f < best_f[idx]
        best_f[idx[better]] = f[better]
        best_X[idx[better]] = X[idx[better]]
        g = g[:, :-1]
        Pi = P[idx]
        Pg = np.einsum("kij,kj->ki", Pi, g)
        gPg = np.einsum("ki,ki->k", g, Pg)
        lower[idx] = np.maximum(lower[idx], f - np.sqrt(np.maximum(gPg, 0.0)))
        done = (gPg <= 1e-300) | (best_f[idx] - lower[idx] < tol)
        active[idx[done]] = False
        go = ~done
        Pg_n = Pg[go] / np.sqrt(gPg[go])[:, None]
        k = idx[go]
        X[k, :-1] -= Pg_n / (n + 1)
        if n == 1:
            # one free variable: the central cut halves the interval (bisection)
            P[k] = Pi[go] / 4.0
        else:
            P[k] = (n * n / (n * n - 1.0)) * (Pi[go] - (2.0 / (n + 1)) * Pg_n[:, :, None] * Pg_n[:, None, :])
    return np.exp(best_f), best_X


def _intervals(H, S: BlockStructure, X, level: float, reach: float, steps: int = 24):
    """For each free block k and frequency, the interval of log d_k (others at ``X``)
    where sigma_max(D M D^-1) <= level, clipped to ``X +/- reach``.  sigma_max is
    log-convex in log d_k, so each end is found by bisection."""
    nw, m = X.shape
    lo = np.empty((nw, m - 1))
    hi = np.empty((nw, m - 1))
    for k in range(m - 1):
        for sign, out in ((1.0, hi), (-1.0, lo)):
            a = np.zeros(nw)                 # feasible offset
            b = np.full(nw, reach)           # offset to test
            Xt = X.copy()
            Xt[:, k] = X[:, k] + sign * b
            ok = _scaled_norms(H, S, Xt) <= level
            a[ok] = b[ok]
            todo = ~ok
            if np.any(todo):
                bb = b.copy()
                for _ in range(steps):
                    mid = 0.5 * (a + bb)
                    Xt[:, k] = X[:, k] + sign * mid
                    good = _scaled_norms(H, S, Xt) <= level
                    a = np.where(todo & good, mid, a)
                    bb = np.where(todo & ~good, mid, bb)
            out[:, k] = X[:, k] + sign * a
    return lo, hi


#: a fit is good enough when it stays inside half of its admissible band (weighted
#: error <= 0.5); 1.0 leaves no slack for several blocks deviating together
_GOOD = 0.5


def _d_step(omega, H, S: BlockStructure, X, upper, max_order: int, fit_tol: float,
            budget: int, reach: float = np.log(100.0), rounds: int = 4, progress=None):
    """Rational scalings for the next K step (see the module docstring).

    ``budget`` bounds the states the scalings add to the plant (a block of
    size ``rows x cols`` with a fit of order ``n`` adds ``n (rows + cols)``).
    Returns the list of fits (``None`` for the last block) and the peak of
    sigma_max(D_fit M D_fit^-1) on the grid, the level the next K step starts from.
    ``progress(text)``, if given, is called before each fit.
    """
    level = float(np.max(upper)) * (1.0 + fit_tol)
    lo, hi = _intervals(H, S, X, level, reach)
    center = 0.5 * (lo + hi)
    half = np.maximum(0.5 * (hi - lo), 1e-4)
    m = len(S)
    cost = [b.rows + b.cols for b in S.blocks]
    requested = [0] * (m - 1)
    best = None
    for _ in range(rounds):
        cache = {}

        def fit(k, n):
            if (k, n) not in cache:
                if progress is not None:
                    progress(f"block {k + 1}/{m - 1}, order {n}")
                try:
                    cache[k, n] = fit_dscale(omega, np.exp(center[:, k]), n, weight=1.0 / half[:, k])
                except (SolverError, ModelError, np.linalg.LinAlgError):
                    cache[k, n] = None
            return cache[k, n]
        cur = []
        for k in range(m - 1):
            f = fit(k, requested[k])
            while f is None and requested[k] > 0:     # a failed order: fall back
                requested[k] -= 1
                f = fit(k, requested[k])
            if f is None:
                raise SolverError(f"D step: no D-scale fit succeeded for block {k} "
                                  f"({S.blocks[k].name or S.blocks[k].kind})")
            cur.append(f)
        # raise the order of the worst-fitted block while the state budget allows;
        # a fit counts as good when it stays inside half of its admissible band
        while True:
            used = sum(f.order * cost[k] for k, f in enumerate(cur))
            cand = [k for k in range(m - 1) if cur[k].error > _GOOD and requested[k] < max_order
                    and used - cur[k].order * cost[k] + (requested[k] + 1) * cost[k] <= budget]
            if not cand:
                break
            k = max(cand, key=lambda k: cur[k].error)
            requested[k] += 1
            f = fit(k, requested[k])
            if f is not None and f.error < cur[k].error:
                cur[k] = f
        fits = cur + [None]
        Xf = np.zeros_like(X)
        for k in range(m - 1):
            Xf[:, k] = np.log(np.abs(fits[k](omega)))
        sig = _scaled_norms(H, S, Xf)
        fpeak = float(sig.max())
        if best is None or fpeak < best[1]:
            best = (fits, fpeak)
        bad = sig > level * (1.0 + 0.25 * fit_tol)
        if not np.any(bad):
            break
        # the fits together exceed the level where each alone stays inside its
        # band: narrow the bands there and fit again
        half[bad] *= 0.4
    return best


# ----------------------------------------------------------------------------
# D-K iteration
# ----------------------------------------------------------------------------

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


@dataclass
class _KStep:
    K: ct.StateSpace
    gamma: float
    method: str


def _k_step(PD, nmeas, ncon):
    """:func:`mutext.hinf.hinfsyn` at a level 0.1 % above the optimum, slycot as fallback.

    D-K iteration gains nothing from the last 0.1 % of a K step, and a tighter
    target would send hinfsyn through its back-off schedule on the plants
    where only an LMI controller can be built.  If no controller of ours
    passes, slycot's Riccati synthesis is tried;
    :func:`mutext.hinf.slycot_hinfsyn` accepts its controller only after
    rebuilding the closed loop (stability, norm).  ``method`` says how the
    controller was built: ``"central"`` (our Riccati central controller),
    ``"lmi"`` (our LMI reconstruction) or ``"slycot"``.
    """
    try:
        res = hinfsyn(PD, nmeas, ncon, backoff=1e-3, max_backoff=1e-3)
        return _KStep(res.K, float(res.gamma), _construction(res))
    except (InfeasibleError, SolverError) as exc:
        first = exc
    try:
        # the full back-off schedule: singular plants (model-based identification)
        # often need a few percent
        res = hinfsyn(PD, nmeas, ncon, backoff=3e-3)
        return _KStep(res.K, float(res.gamma), _construction(res))
    except (InfeasibleError, SolverError):
        pass
    ref = slycot_hinfsyn(PD, nmeas, ncon, timeout=60.0)
    if ref.status == "verified":
        return _KStep(ref.K, float(ref.achieved), "slycot")
    raise first


def _k_step_lmi_first(PD, nmeas, ncon):
    """The LMI controller (:func:`mutext.hinf.hinfsyn` with ``method="lmi"``, 0.1 %
    above the optimum) where it passes its check, :func:`_k_step` otherwise."""
    try:
        res = hinfsyn(PD, nmeas, ncon, method="lmi", backoff=1e-3, max_backoff=1e-3)
        return _KStep(res.K, float(res.gamma), "lmi")
    except (InfeasibleError, SolverError):
        return _k_step(PD, nmeas, ncon)


def _construction(res) -> str:
    """Short name of how :func:`mutext.hinf.hinfsyn` built its controller."""
    return "central" if res.construction.startswith("central") else "lmi"


def _k_step_riccati(PD, nmeas, ncon):
    """slycot's Riccati synthesis, accepted after :func:`mutext.hinf.slycot_hinfsyn`
    verified it (closed loop rebuilt: stable, norm as claimed); :func:`_k_step` otherwise."""
    ref = slycot_hinfsyn(PD, nmeas, ncon, timeout=60.0)
    if ref.status == "verified":
        return _KStep(ref.K, float(ref.achieved), "slycot")
    return _k_step(PD, nmeas, ncon)


def _print(out, text):
    if out is not None:
        print(text, file=out, flush=True)


#: a stable pole counts as near the axis when its magnitude is below this fraction of the
#: smallest magnitude of the plant's other poles (a cluster at least three decades below the rest)
NEAR_AXIS_GAP = 1e-3


def near_axis_poles(P, gap: float = NEAR_AXIS_GAP) -> np.ndarray:
    r"""Poles of ``P`` in the closed left half plane, or at 0, that lie far below the rest.

    A pole :math:`p` with :math:`|p| <` ``gap`` times the smallest magnitude of the
    poles above it (sorted by magnitude, the first gap of that size from below
    separates the cluster): typically a weight that approximates an integrator
    by a pole at -1e-6 rad/s, or an exact integrator.  Poles in the open right
    half plane are never listed.
    """
    P = as_ss(P)
    if P.nstates == 0:
        return np.zeros(0, complex)
    p = np.linalg.eigvals(np.asarray(P.A, float))
    p = p[np.argsort(np.abs(p))]
    mags = np.abs(p)
    for k in range(p.size - 1):
        if mags[k] < gap * mags[k + 1]:
            low = p[:k + 1]
            return low[low.real <= 0]
    return np.zeros(0, complex)


def _default_dk_grid(P, n: int) -> np.ndarray:
    """Log grid over the plant's dynamics (1.5 decades beyond its pole magnitudes),
    leaving out near-axis poles (:func:`near_axis_poles`; see the module docstring)."""
    near = near_axis_poles(P)
    if near.size:
        P = as_ss(P)
        p = np.linalg.eigvals(np.asarray(P.A, float))
        rest = p[np.abs(p) > np.abs(near).max()]
        lo, hi = np.abs(rest).min() / 10 ** 1.5, np.abs(rest).max() * 10 ** 1.5
        return _clip_grid(default_grid(P, n=n, decades=1.5), lo, hi, n)
    return default_grid(P, n=n, decades=1.5)


def _clip_grid(w, lo, hi, n):
    """``n`` log-spaced points on [lo, hi] plus the points of ``w`` inside it (resonances)."""
    inside = w[(w >= lo) & (w <= hi)]
    return np.unique(np.concatenate([np.logspace(np.log10(lo), np.log10(hi), n), inside]))


def _local_maxima(values, count):
    """Indices of the ``count`` largest local maxima (plateaus included), largest first."""
    v = np.asarray(values)
    pk = [i for i in range(v.size) if (i == 0 or v[i] >= v[i - 1]) and (i == v.size - 1 or v[i] >= v[i + 1])]
    return sorted(pk, key=lambda i: -v[i])[:count]


def _around_peaks(w, values, npeaks: int, points: int, floor: float = -np.inf) -> list:
    """``points`` log-spaced frequencies strictly between the neighbours of each of the
    ``npeaks`` largest local maxima of ``values`` on the grid ``w`` (those at least ``floor``)."""
    out = []
    for i in _local_maxima(values, npeaks):
        if values[i] < floor:
            break
        a, b = w[max(i - 1, 0)], w[min(i + 1, w.size - 1)]
        if b > a:
            out.append(np.logspace(np.log10(a), np.log10(b), points + 2)[1:-1])
    return out


def _refine_around_maxima(w, data, evaluate, rounds, points: int):
    """The grid ``w`` (sorted) and the arrays ``data`` on it (``data[0]`` the values), with
    ``points`` log-spaced frequencies added between the neighbours of local maxima, round by
    round: ``rounds`` holds ``(npeaks, within)``, the ``npeaks`` largest maxima at least
    ``1 - within`` times the peak (``within=None``: all of them).  ``evaluate(wn)`` returns the
    data at new frequencies.  Each round shrinks the spacing at a maximum by ``points + 1``,
    and a smooth peak's error by its square.  Returns the grid, the data and the frequencies
    added."""
    added = []
    for npeaks, within in rounds:
        values = data[0]
        floor = -np.inf if within is None else values.max() * (1.0 - within)
        new = _around_peaks(w, values, npeaks, points, floor=floor)
        wn = np.setdiff1d(np.concatenate(new), w) if new else np.zeros(0)
        if wn.size == 0:
            break
        dn = evaluate(wn)
        added.append(wn)
        order = np.argsort(np.concatenate([w, wn]))
        w = np.concatenate([w, wn])[order]
        data = tuple(np.concatenate([a, b])[order] for a, b in zip(data, dn))
    return w, data, (np.concatenate(added) if added else np.zeros(0))


def _fine_sweep(CL, S: BlockStructure, omega, npeaks: int = 4, rounds: int = 3, points: int = 16,
                progress=None) -> tuple[MuSweep, np.ndarray]:
    """Diagonal-D upper bound on ``omega`` with its largest local maxima refined:
    ``rounds`` times, ``points`` log-spaced frequencies between the neighbours of
    each peak are added (each round shrinks the spacing there by ``points + 1``).
    Returns the sweep and the loop's response on its grid, (nw, ncols, nrows)."""
    w = np.unique(np.asarray(omega, float))
    H = np.moveaxis(freqresp(CL, w), -1, 0)
    up, X = _sweep_upper(H, S, progress=progress)

    def evaluate(wn):
        Hn = np.moveaxis(freqresp(CL, wn), -1, 0)
        return (*_sweep_upper(Hn, S), Hn)

    w, (up, X, H), _ = _refine_around_maxima(w, (up, X, H), evaluate, [(npeaks, None)] * rounds, points)
    k = int(np.argmax(up))
    return MuSweep(w, up, np.full(w.size, np.nan), np.exp(X), "osborne", float(up[k]), float(w[k]),
                   float("nan"), float("nan"), None, ["osborne"] * w.size), H


def _dg_values(H, S: BlockStructure, upper) -> np.ndarray:
    """min(D-G bound, complex bound ``upper``) over the grid, both certified at each frequency,
    where it can decide the peak (zero elsewhere).  The D-G bound
    (``mutext.mu.mu_upper(method="fast")``) is computed from the largest complex values down,
    until the next complex value cannot raise the peak.  Where the complex bound is flat (an
    equalised D-K loop) that is every frequency of the flat part: stopping earlier would report
    the complex value of a frequency whose D-G bound is lower, and miss the gain of a controller
    that exploits the real parameters."""
    dg = np.zeros(len(upper))
    best = 0.0
    for k in np.argsort(-np.asarray(upper)):
        if upper[k] <= best:
            break
        dg[k] = min(mu_upper(H[k], S, method="fast").value, float(upper[k]))
        best = max(best, dg[k])
    return dg


def _dg_peak(H, S: BlockStructure, upper) -> tuple[float, int]:
    """Peak over the grid of :func:`_dg_values` and its index in the grid."""
    dg = _dg_values(H, S, upper)
    k = int(np.argmax(dg))
    return float(dg[k]), k


def _dg_refined_peak(CL, H, S: BlockStructure, omega, upper, rounds=((8, 0.02), (4, 0.002)),
                     points: int = 6) -> tuple[float, float, np.ndarray]:
    """The D-G peak of :func:`_dg_peak` with the local maxima of the D-G bound refined
    (:func:`_refine_around_maxima`; by default the 8 largest within 2 % of the peak, then the
    4 largest within 0.2 %).  A controller that exploits the real parameters equalises the
    D-G bound, so many local maxima are nearly equal and the true peak can lie between the
    points of a grid refined around the complex bound's peaks.  Returns the peak, its
    frequency and the frequencies added."""
    def evaluate(wn):
        Hn = np.moveaxis(freqresp(CL, wn), -1, 0)
        return (np.array([mu_upper(h, S, method="fast").value for h in Hn]),)

    w, (dg,), added = _refine_around_maxima(np.asarray(omega, float), (_dg_values(H, S, upper),), evaluate,
                                            rounds, points)
    k = int(np.argmax(dg))
    return float(dg[k]), float(w[k]), added


def branch_mu(result: "DKResult", structure: BlockStructure, *, rtol: float = 1e-3,
              max_boxes: int = 2000) -> BranchPeak:
    r"""The loop's :math:`\mu` by branch and bound on its real parameters, on the final grid.

    The D-G bound of a loop with real parameters can lie well above :math:`\mu`
    when their ranges are wide; :func:`mutext.mu.branch_peak` closes that gap
    with a certified bound (the boxes of the parameters' ranges bounded one by
    one).  The grid is that of the result's final analysis (``result.sweep``),
    with the D-G bound's largest maxima refined as in :func:`dk_iteration`; the
    complex bound of the sweep spares the points that cannot decide the peak.

    Parameters
    ----------
    result : DKResult
        From :func:`dk_iteration`, :func:`dgk_iteration` or :func:`refine_controller`.
    structure : BlockStructure
        The structure the result was computed for.
    rtol, max_boxes
        As for :func:`mutext.mu.mu_upper_branch`.

    Returns
    -------
    mutext.mu.BranchPeak
        ``value`` bounds :math:`\mu` of ``result.CL`` at every frequency of the grid; ``dg``
        is the D-G peak on the same grid.

    Examples
    --------
    The three-mass rig with 10 % uncertainty (trial 5) at :math:`W_z` = 4.7 mm: the D-G bound of
    the D-K loop reads 1.006, branch and bound proves :math:`\mu < 1`, within 1 % of the
    lower bound (about 20 s, so not run with the other examples; ``tests/test_mu_branch.py`` checks
    a loop of this rig against brute force and AB13MD):

    >>> from mutext.examples import three_mass as tm
    >>> from mutext.mbi import mbi_plant
    >>> args = tm.mbi_arguments(tm.TRIALS["5"])
    >>> plant = mbi_plant(args.pop("true"), args.pop("engineering"), Wz=4.7e-3, **args)
    >>> res = dk_iteration(plant.P, plant.structure, 1, 1, max_iter=2,
    ...                    synthesis="lmi-first")  # doctest: +SKIP
    >>> b = branch_mu(res, plant.structure)  # doctest: +SKIP
    >>> print(f"D-G {b.dg:.4f}, branch and bound {b.value:.4f}, lower {res.mu_lower:.4f}")  # doctest: +SKIP
    D-G 1.0056, branch and bound 0.9955, lower 0.9881
    """
    S = structure
    if not isinstance(S, BlockStructure):
        raise ModelError(f"structure must be a BlockStructure, got {type(S).__name__}")
    CL, sweep = result.CL, result.sweep
    if CL.noutputs != S.ncols or CL.ninputs != S.nrows:
        raise ModelError(f"the result's loop has {CL.noutputs} outputs and {CL.ninputs} inputs, but the "
                         f"structure needs {S.ncols} and {S.nrows}")
    w = np.asarray(sweep.omega, float)
    H = np.moveaxis(freqresp(CL, w), -1, 0)
    upper = np.asarray(sweep.upper, float)
    if S.has_real:
        # the D-G bound's maxima, refined: their frequencies join the grid
        _, _, added = _dg_refined_peak(CL, H, S, w, upper)
        if added.size:
            Ha = np.moveaxis(freqresp(CL, added), -1, 0)
            w, H = np.concatenate([w, added]), np.concatenate([H, Ha])
            upper = np.concatenate([upper, np.full(added.size, np.inf)])
    return branch_peak(H, S, upper=upper, rtol=rtol, max_boxes=max_boxes)


def _final_analysis(CL, S: BlockStructure, grid, final_points: int, dg: bool, npeaks: int = 4,
                    report=None):
    """Certified complex upper bound on a fine grid, lower bounds at the peaks and the D-G bound
    (refined around its own peaks).  Returns the complex sweep, the real and complex lower
    bounds, the D-G peak and the frequencies added for it."""
    beat = report                   # no heartbeat thread when nobody listens
    report = report or (lambda stage, fraction: None)
    Sc = S.complexified()
    fine = np.unique(np.concatenate([default_grid(CL, n=final_points, decades=1.5), grid]))
    final, H = _fine_sweep(CL, Sc, fine, npeaks=npeaks,
                        progress=lambda f: report(f"final-analysis: mu sweep, {fine.size} frequencies", 0.4 * f))
    ups = final.upper
    wpk = final.omega[_local_maxima(ups, npeaks)]
    mu_dg = float(final.peak_upper)
    wreal, extra = wpk, np.zeros(0)
    if S.has_real and dg:
        # minutes on large loops, in one call: a heartbeat with the elapsed time
        with _Heartbeat(beat, lambda t: f"final-analysis: D-G bound ({t:.0f} s)", 0.4):
            mu_dg, w_dg, extra = _dg_refined_peak(CL, H, S, final.omega, ups)
        # the real lower bound also where the D-G bound peaks: a loop that uses the
        # parameters' realness has its complex peaks elsewhere
        wreal = np.union1d(wpk, [w_dg])
    with _Heartbeat(beat, lambda t: f"final-analysis: lower bounds at the peaks ({t:.0f} s)", 0.7):
        low_c = mu_sweep(CL, Sc, wpk, method="osborne", lower="all", refine=False)
        low = mu_sweep(CL, S, wreal, method="osborne", lower="all", refine=False) if S.has_real else low_c
    final.lower = np.full(final.omega.size, np.nan)
    final.lower[np.searchsorted(final.omega, low.omega)] = low.lower
    final.peak_lower = float(low.peak_lower)
    final.lower_frequency = float(low.lower_frequency)
    final.lower_delta = low.lower_delta
    return final, float(low.peak_lower), float(low_c.peak_lower), mu_dg, extra


def dk_iteration(P, structure: BlockStructure, nmeas: int, ncon: int, *, omega=None,
                 max_iter: int = 8, max_order: int = 4, max_states: int | None = None,
                 fit_tol: float = 0.02, rel_improvement: float = 0.01, patience: int = 1,
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
        ``(rows + cols) * order`` per block (default ``P.nstates + 12``).  The
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
    :math:`x_1` at 0.043 m and +/-2 % on every parameter, on half the default
    grids (a few seconds):

    >>> from mutext.examples import two_mass_uncertain as tmu
    >>> res = dk_iteration(tmu.plant(0.043), tmu.structure(), 1, 1, grid_points=40, final_points=100)
    >>> bool(res.mu_upper < 1), bool(res.mu_lower <= res.mu_upper)
    (True, True)
    >>> res.controller_order <= tmu.plant(0.043).nstates + 12
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
        max_states = P.nstates + 12
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


class _Heartbeat:
    """While a step that cannot report itself runs (the K step's SDP solve), call
    ``progress(stage(elapsed), fraction)`` at its start and about every ``period``
    seconds from a helper thread."""

    def __init__(self, progress, stage, fraction: float, period: float = 1.0):
        self.progress, self.stage, self.fraction, self.period = progress, stage, fraction, period
        self.thread = None

    def __enter__(self):
        if self.progress is None:
            return self
        import threading
        self.t0 = time.perf_counter()
        self.stop = threading.Event()
        self.progress(self.stage(0.0), self.fraction)

        def beat():
            while not self.stop.wait(self.period):
                self.progress(self.stage(time.perf_counter() - self.t0), self.fraction)
        self.thread = threading.Thread(target=beat, daemon=True)
        self.thread.start()
        return self

    def __exit__(self, *exc):
        if self.thread is not None:
            self.stop.set()
            self.thread.join()
        return False


def _dk(P, S, nmeas, ncon, grid, max_iter, max_order, budget, fit_tol, rel_improvement, patience,
        grid_points, final_points, dg, synth, out, t0, on_progress=None, as_given=None,
        real_scale: float = 1.0):
    """The iteration on ``P``; the best controller's final analysis on the loop of ``as_given``
    (default ``P``), the plant :func:`dgk_iteration` judges every try on."""
    Sc = S.complexified()
    if grid is None:
        grid = _default_dk_grid(P, grid_points)

    def at(it, part):
        """Overall fraction at ``part`` (0-1) of iteration ``it``."""
        return 0.9 * (it - 1 + part) / max_iter

    def report(stage, fraction):
        if on_progress is not None:
            on_progress(stage, min(max(fraction, 0.0), 1.0))

    def kstep(it, PD):
        stage = (lambda el: f"K-step {it}/{max_iter}: H-infinity synthesis, {PD.nstates} states, {el:.0f} s")
        with _Heartbeat(on_progress, stage, at(it, 0.0)):
            return synth(PD, nmeas, ncon)

    def dstep(it, H, X, upper, order):
        return _d_step(grid, H, S, X, upper, order, fit_tol, budget,
                       progress=lambda text: report(f"D-fit {it}/{max_iter}: {text}", at(it, 0.9)))
    real_blocks = [k for k, b in enumerate(S.blocks) if b.kind == "real"]
    gcol = f" {'real blocks':>11}" if real_blocks else ""
    gtxt = (f" {'complex' if real_scale == 1.0 else f'c = {real_scale:.3f}':>11}" if real_blocks else "")
    dgcol = f" {'mu D-G':>8}" if real_blocks and dg else ""
    Xd = None          # log D scalings on the grid, the next sweep's starting point
    fits = [None] * len(S)
    fit_peak = float("nan")
    history, notes = [], []
    best = lowest = None
    stall = 0
    _print(out, f"{'iter':>4} {'gamma (K step)':>15} {'peak mu':>10}{dgcol} {'D-fit orders':>18}{gcol} "
                f"{'K order':>8} {'plant':>6} {'seconds':>8}")
    for it in range(1, max_iter + 1):
        ti = time.perf_counter()
        orders = [0 if f is None else f.order for f in fits[:-1]]
        PD = P if it == 1 else scaled_plant(P, S, fits, nmeas, ncon)
        try:
            try:
                res = kstep(it, PD)
            except (InfeasibleError, SolverError, IllPosedError) as exc:
                if best is None or not any(orders):
                    raise
                # Lower-order scalings spread the scaled plant's eigenvalues less,
                # which is what usually defeats the LMI solver: retry once.
                first = f"iteration {it}: the K step failed with D-fit orders {orders} ({exc})"
                fits, fit_peak = dstep(it, H, Xd, upper, max(orders) - 1)
                orders = [f.order for f in fits[:-1]]
                PD = scaled_plant(P, S, fits, nmeas, ncon)
                res = kstep(it, PD)
                notes.append(first + f"; retried with orders {orders}")
        except (InfeasibleError, SolverError, IllPosedError) as exc:
            if best is None:
                raise
            notes.append(f"iteration {it}: the K step failed ({exc}); kept iteration {best[4]}")
            history.append({"iteration": it, "gamma": float("nan"), "mu": float("nan"),
                            "mu_dg": float("nan"), "orders": orders,
                            "g_orders": [None] * len(real_blocks), "real_scale": real_scale,
                            "plant_states": int(PD.nstates), "fit_peak": fit_peak, "controller_order": None,
                            "method": None, "seconds": time.perf_counter() - ti, "error": str(exc)})
            msg = str(exc)
            _print(out, f"{it:>4}  K step failed: {msg[:90] + ' ...' if len(msg) > 90 else msg}")
            break
        K = as_ss(res.K, "K")
        CL = lft_lower(P, K, nmeas, ncon)
        poles = np.linalg.eigvals(np.asarray(CL.A, float)) if CL.nstates else np.zeros(0)
        if poles.size and poles.real.max() >= 0:
            # D-hat is stable and minimum phase, so K stabilises P iff it stabilises D P D^-1
            exc = SolverError(f"iteration {it}: the K-step controller does not stabilise the plant "
                              f"(closed-loop pole with real part {poles.real.max():.3g})")
            if best is None:
                raise exc
            notes.append(str(exc))
            _print(out, f"{it:>4}  {exc}")
            break
        H = np.moveaxis(freqresp(CL, grid), -1, 0)
        upper, Xd = _sweep_upper(H, Sc, Xd, progress=lambda f: report(
            f"mu-sweep {it}/{max_iter}: {grid.size} frequencies, {100 * f:.0f} % converged", at(it, 0.6 + 0.3 * f)))
        mu_pk = float(upper.max())
        mu_dg_pk = mu_pk
        if real_blocks and dg:
            # the bound with the real blocks real (fast D-G sweep, no LMI check), pointwise
            # no higher than the complex one: both are certified at each frequency
            report(f"mu-sweep {it}/{max_iter}: D-G bound at the peaks", at(it, 0.9))
            mu_dg_pk = _dg_peak(H, S, upper)[0]
        row = {"iteration": it, "gamma": float(res.gamma), "mu": mu_pk, "mu_dg": mu_dg_pk, "orders": orders,
               "g_orders": [None] * len(real_blocks), "real_scale": real_scale,
               "plant_states": int(PD.nstates), "fit_peak": fit_peak, "controller_order": int(K.nstates),
               "method": getattr(res, "method", "custom"),
               "seconds": time.perf_counter() - ti}
        history.append(row)
        progress = lowest is None or mu_pk < lowest * (1.0 - rel_improvement)
        lowest = mu_pk if lowest is None else min(lowest, mu_pk)
        # the loop kept is the one with the lowest bound that will be reported: with real blocks,
        # the D-G bound (a D step that lowers the complex bound can raise it: the fitted D scalings
        # treat the real parameters as complex)
        if best is None or mu_dg_pk < best[0]:
            best = (mu_dg_pk, K, CL, list(fits), it)
        stall = 0 if progress else stall + 1
        # a single block has no scaling to fit: the first K step is the answer
        stop = stall >= patience or it == max_iter or len(S) == 1
        if not stop:
            # D step on the new closed loop
            try:
                fits_new, fit_peak = dstep(it, H, Xd, upper, max_order)
            except SolverError as exc:
                notes.append(f"iteration {it}: {exc}")
                stop = True
            else:
                fits = fits_new
        row["seconds"] = time.perf_counter() - ti
        dgtxt = f" {mu_dg_pk:>8.5f}" if dgcol else ""
        _print(out, f"{it:>4} {res.gamma:>15.5f} {mu_pk:>10.5f}{dgtxt} {str(orders):>18}{gtxt} {K.nstates:>8} "
                    f"{PD.nstates:>6} {row['seconds']:>8.2f}")
        if stop:
            break
    _, K, CL, used_fits, best_it = best
    if as_given is not None:
        P = as_given
        CL = lft_lower(P, K, nmeas, ncon)
    near = near_axis_poles(P)
    cl_poles = np.linalg.eigvals(np.asarray(CL.A, float)) if CL.nstates else np.zeros(0)
    max_re = float(cl_poles.real.max()) if cl_poles.size else float("-inf")
    if near.size:
        notes.append(f"near-axis poles of the plant at {', '.join(f'{p.real:.3g}' for p in near)} rad/s: "
                     f"left out of the D-step grid (from {grid.min():.3g} rad/s), covered by the final "
                     f"analysis; the closed loop of the plant as given is "
                     f"{'stable' if max_re < 0 else 'NOT stable'} (largest pole real part {max_re:.3g})")
    final, low, low_c, mu_dg, _ = _final_analysis(
        CL, S, grid, final_points, dg,
        report=None if on_progress is None else (lambda stage, f: report(stage, 0.9 + 0.1 * f)))
    report("final-analysis: done", 1.0)
    _print(out, f"best: iteration {best_it}, controller order {K.nstates}; fine grid: "
                f"{low:.4f} <= mu <= {final.peak_upper:.4f}"
                + (" (real parameters as complex)" if S.has_real else "")
                + (f", {mu_dg:.4f} with D-G scalings" if S.has_real and dg else ""))
    return DKResult(K=K, CL=CL, mu_upper=float(final.peak_upper), mu_upper_dg=mu_dg, mu_lower=low,
                    mu_lower_complex=low_c, peak_frequency=float(final.peak_frequency),
                    history=history, sweep=final, fits=used_fits, seconds=time.perf_counter() - t0,
                    best_iteration=best_it, notes=notes, near_axis_poles=near, max_pole_real=max_re,
                    real_scale=real_scale)


# ----------------------------------------------------------------------------
# real parameters kept real: D-G-K by the range the K steps see
# ----------------------------------------------------------------------------

def real_scaled_plant(P, structure: BlockStructure, scale: float, nmeas: int, ncon: int) -> ct.StateSpace:
    r"""``P`` with the outputs of its real blocks multiplied by ``scale``.

    The loop :math:`\mathcal F_u(P_c, \Delta)` with :math:`P_c` the returned
    plant and a real block :math:`|\delta| \le 1` is the loop of ``P`` with
    :math:`|\delta| \le c`: the parameters' ranges shrunk by the factor
    :math:`c` = ``scale``, every other block unchanged.  No states are added.
    """
    P = as_ss(P, "P")
    if not isinstance(structure, BlockStructure):
        raise ModelError(f"structure must be a BlockStructure, got {type(structure).__name__}")
    _check_sizes(P, structure, nmeas, ncon)
    if not (np.isfinite(scale) and 0.0 < scale <= 1.0):
        raise ModelError(f"scale must lie in (0, 1], got {scale!r}")
    rows = np.ones(P.noutputs)
    for k, b in enumerate(structure.blocks):
        if b.kind == "real":
            rows[structure.col_slices[k]] = scale
    L = np.diag(rows)
    return ss(P.A, P.B, L @ np.asarray(P.C, float), L @ np.asarray(P.D, float),
              inputs=P.input_labels, outputs=P.output_labels)


def dgk_iteration(P, structure: BlockStructure, nmeas: int, ncon: int, *, step: float = 0.03,
                  max_tries: int = 6, out=None, progress=None, **options) -> DKResult:
    r"""Mu-synthesis with the real parameters kept real (D-G-K by a search over their range).

    D-K iteration (:func:`dk_iteration`) scales real parameters as complex
    ones.  That costs nothing where the loop is nearly real (at low frequency)
    and much where it is not: the D-G bound of an equalised D-K loop often lies
    well below its complex bound over a band, and a controller could trade that
    slack for a lower peak.  Here the K steps see the real parameters as
    complex scalars over :math:`c` times their range
    (:func:`real_scaled_plant`), and :math:`c` is chosen by the number that
    matters: the D-G bound (real blocks real) of the loop of the plant *as
    given* with the resulting controller.  The tries are :math:`c = 1` (plain
    D-K), then :math:`1 - \text{step}, 1 - 2\,\text{step}, \dots` while the D-G
    bound falls (if the first step does not help, :math:`1 - \text{step}/2,
    1 - \text{step}/4, \dots` until one does), and one parabolic step between
    the best and its neighbours.

    The approximation: a K step at :math:`c < 1` optimises a problem in which
    the parameters vary less than they do (the one-dimensional counterpart of
    the "mu-K" scaling of Lin, Postlethwaite and Gu [LPG]_, which shrinks the
    real channels by the pointwise ratio of the bounds).  Its level is not a
    bound for the real problem; only the D-G analysis of the loop as given is
    (``mutext.mu.mu_upper(method="fast")`` at every frequency where the complex
    bound could decide the peak, pointwise no higher than the certified complex
    bound).  The controller returned is the try with the lowest D-G bound, so
    never worse than plain D-K with the same options.  A pointwise G fit
    (Young's affine form) or the disc transform (:func:`mutext.mu.dg_disc`)
    would let each frequency use its own disc; the fits of their para-skew
    filters were the obstacle (see the mu chapter of the book).
    :func:`refine_controller` uses the scalings of every frequency without
    fits, by moving the controller this search returns.

    Parameters
    ----------
    P, structure, nmeas, ncon
        As for :func:`dk_iteration`.
    step : float
        Step of the range factor :math:`c` (0 < step < 0.5).
    max_tries : int
        Largest number of D-K runs, the plain one included (>= 2).
    out : file or None
        Where to print each try's iteration table and a summary row.
    progress : callable, optional
        ``progress(stage, fraction)``; stages start with ``"D-G-K try k/n"``.
    **options
        Passed to :func:`dk_iteration` for every try (``max_states``,
        ``fit_tol``, ``max_iter``, ...; ``dg`` must stay True).

    Returns
    -------
    DKResult
        For the best try: ``K`` and ``CL`` (the loop of ``P`` as given),
        ``mu_upper_dg`` its D-G bound, ``mu_upper`` its complex bound,
        ``history`` the iterations of that try (K-step levels and ``mu`` on the
        scaled plant), ``real_scale`` its :math:`c`, ``tries`` all tries,
        ``seconds`` the whole search.

    Raises
    ------
    ModelError
        Bad options (as :func:`dk_iteration`, and ``step``, ``max_tries``), a
        structure without real blocks.

    References
    ----------
    .. [LPG] J. L. Lin, I. Postlethwaite and D.-W. Gu, "mu-K iteration: a new
       algorithm for mu-synthesis", *Automatica* 29 (1993) 219-224.
    .. [Y] P. M. Young, "Controller design with real parametric uncertainty",
       *Int. J. Control* 65 (1996) 469-509.

    Examples
    --------
    The two-mass problem at 0.043 m, plain D-K and one try at c = 0.97, one D-K
    iteration each (the H-infinity designs, about 5 s; ``max_iter=2`` brings the
    D-G bound from 2.93 to 1.004):

    >>> from mutext.examples import two_mass_uncertain as tmu
    >>> res = dgk_iteration(tmu.plant(0.043), tmu.structure(), 1, 1, max_tries=2, max_iter=1)
    >>> [round(t["scale"], 2) for t in res.tries]
    [1.0, 0.97]
    >>> bool(res.mu_upper_dg <= min(t["mu_dg"] for t in res.tries) + 1e-12)
    True
    """
    t0 = time.perf_counter()
    if "dg" in options and not options["dg"]:
        raise ModelError("dgk_iteration judges every try by the D-G bound: dg must be True")
    options.pop("dg", None)
    # the options of dk_iteration's own signature, less those dgk_iteration takes itself
    defaults = {k: v for k, v in dk_iteration.__kwdefaults__.items() if k not in ("dg", "out", "progress")}
    unknown = sorted(set(options) - set(defaults))
    if unknown:
        raise ModelError(f"unknown option(s) for dk_iteration: {', '.join(unknown)}")
    P, S, args = _arguments(P, structure, nmeas, ncon, dg=True, **{**defaults, **options})
    if not S.has_real:
        raise ModelError(f"the structure {S!r} has no real blocks: use dk_iteration")
    if not (isinstance(step, (int, float, np.floating)) and 0.0 < step < 0.5):
        raise ModelError(f"step must lie in (0, 0.5), got {step!r}")
    if not (isinstance(max_tries, (int, np.integer)) and max_tries >= 2):
        raise ModelError(f"max_tries must be an integer >= 2, got {max_tries!r}")
    results, failed = {}, []

    def run(c):
        i = tried() + 1
        _print(out, f"D-G-K try {i}/{max_tries}: the K steps see the real parameters over {c:.4f} x their range")
        rep = None if progress is None else (
            lambda stage, f: progress(f"D-G-K try {i}/{max_tries} (c = {c:.3f}): {stage}",
                                      min(1.0, (i - 1 + f) / max_tries)))
        ti = time.perf_counter()
        Pc = P if c == 1.0 else real_scaled_plant(P, S, c, nmeas, ncon)
        try:
            with blas_single_thread():
                r = _dk(Pc, S, nmeas, ncon, *args, out, ti, rep, as_given=P, real_scale=c)
        except (InfeasibleError, SolverError, IllPosedError) as exc:
            if c == 1.0:
                raise
            failed.append(f"c = {c:.4f}: {str(exc)[:120]}")
            _print(out, f"D-G-K try {i}: the D-K run failed ({str(exc)[:90]})")
            return np.inf
        results[c] = r
        _print(out, f"D-G-K try {i}: loop of the plant as given: mu <= {r.mu_upper_dg:.5f} (D-G), "
                    f"{r.mu_upper:.5f} (complex); controller order {r.K.nstates}; "
                    f"{time.perf_counter() - ti:.1f} s")
        return r.mu_upper_dg

    def value(c):
        c = float(round(c, 6))
        return results[c].mu_upper_dg if c in results else run(c)

    def tried():
        return len(results) + len(failed)

    v1 = value(1.0)
    c = 1.0 - step
    if value(c) < v1:
        while tried() < max_tries - 1 and c - step > 0.0:
            if value(c - step) >= value(c):
                break
            c -= step
    else:
        # no gain one step away: halve the step towards 1 while tries are left
        h = step / 2
        while tried() < max_tries - 1 and h >= step / 16:
            if value(1.0 - h) < v1:
                break
            h /= 2
    # one parabolic step through the best try and its neighbours
    cs = sorted(results)
    best = min(cs, key=lambda x: results[x].mu_upper_dg)
    k = cs.index(best)
    if tried() < max_tries and 0 < k < len(cs) - 1:
        (a, fa), (b, fb), (d, fd) = [(x, results[x].mu_upper_dg) for x in cs[k - 1:k + 2]]
        den = (b - a) * (fb - fd) - (b - d) * (fb - fa)
        if den != 0.0:
            cn = b - 0.5 * ((b - a) ** 2 * (fb - fd) - (b - d) ** 2 * (fb - fa)) / den
            if a < cn < d and min(abs(cn - a), abs(cn - b), abs(cn - d)) > 0.1 * step:
                value(cn)
    best = min(results, key=lambda x: results[x].mu_upper_dg)
    r = results[best]
    r.tries = [{"scale": c, "mu_dg": results[c].mu_upper_dg, "mu": results[c].mu_upper,
                "mu_lower": results[c].mu_lower, "controller_order": results[c].K.nstates,
                "iterations": len(results[c].history), "seconds": results[c].seconds}
               for c in results]
    r.seconds = time.perf_counter() - t0
    if failed:
        r.notes.append("D-G-K: failed tries (" + "; ".join(failed) + ")")
    r.notes.append(f"D-G-K: {len(results)} D-K runs with the real parameters' ranges scaled by "
                   + ", ".join(f"{c:.4f}" for c in results) + f"; the best, {best:.4f}, gives the loop of "
                   f"the plant as given mu <= {r.mu_upper_dg:.5f} with D-G scalings (plain D-K: {v1:.5f})")
    _print(out, f"D-G-K best: c = {best:.4f}, mu <= {r.mu_upper_dg:.5f} (D-G), plain D-K {v1:.5f}")
    return r


# ----------------------------------------------------------------------------
# the controller refined with the D-G scalings of every frequency (no fits)
# ----------------------------------------------------------------------------

class _Modal:
    r"""A controller in real modal form, each mode's input and output balanced.

    Parameters ``theta``: the real parts and imaginary parts of the modes (one
    per real mode, two per complex pair: the block
    :math:`\begin{bmatrix}\sigma & \omega\\ -\omega & \sigma\end{bmatrix}`),
    then ``B`` (row-major), ``C`` (row-major) and ``D``; ``scale`` the size of
    each, which sets the trust region.
    """

    def __init__(self, K):
        A, B, C, D = (np.asarray(X, float) for X in (K.A, K.B, K.C, K.D))
        n = A.shape[0]
        self.n, self.ny, self.nu = n, B.shape[1], C.shape[0]
        cols, size = [], []
        if n:
            lam, V = np.linalg.eig(A)
            order = np.lexsort((-lam.imag, np.round(lam.real, 10)))
            lam, V = lam[order], V[:, order]
            _, T = cdf2rdf(lam, V)
            self.cond = float(np.linalg.cond(T))
            if not np.isfinite(self.cond) or self.cond > 1e10:
                raise ModelError(f"the controller has no usable modal form (eigenvector condition number "
                                 f"{self.cond:.3g}: repeated or defective poles)")
            Ti = np.linalg.inv(T)
            A, B, C = Ti @ A @ T, Ti @ B, C @ T
            i = 0
            g = np.ones(n)
            while i < n:
                m = 2 if (i + 1 < n and abs(A[i, i + 1]) > 1e-12 * (1.0 + abs(A[i, i]))) else 1
                e = np.zeros((n, n))
                e[i:i + m, i:i + m] = np.eye(m)
                cols.append(e.ravel())
                if m == 2:
                    e = np.zeros((n, n))
                    e[i, i + 1], e[i + 1, i] = 1.0, -1.0
                    cols.append(e.ravel())
                    size += [np.hypot(A[i, i], A[i, i + 1])] * 2
                else:
                    size.append(abs(A[i, i]))
                gb = np.linalg.norm(B[i:i + m]) + 1e-300
                gc = np.linalg.norm(C[:, i:i + m]) + 1e-300
                g[i:i + m] = np.sqrt(gc / gb)
                i += m
            B, C = B * g[:, None], C / g[None, :]
        else:
            self.cond = 1.0
        self.E = np.array(cols).T if cols else np.zeros((0, 0))
        thA = np.linalg.lstsq(self.E, A.ravel(), rcond=None)[0] if n else np.zeros(0)
        self.na = thA.size
        self.theta = np.concatenate([thA, B.ravel(), C.ravel(), D.ravel()])
        ref = max(np.abs(self.theta).max(), 1e-12)
        self.scale = np.concatenate([np.maximum(size, 1e-9 * ref), np.abs(B.ravel()), np.abs(C.ravel()),
                                     np.abs(D.ravel())])
        self.scale = np.maximum(self.scale, 1e-6 * ref)

    def matrices(self, theta):
        n, ny, nu, na = self.n, self.ny, self.nu, self.na
        A = (self.E @ theta[:na]).reshape(n, n) if n else np.zeros((0, 0))
        B = theta[na:na + n * ny].reshape(n, ny)
        C = theta[na + n * ny:na + n * ny + nu * n].reshape(nu, n)
        D = theta[na + n * ny + nu * n:].reshape(nu, ny)
        return A, B, C, D

    def ss(self, theta):
        return ss(*self.matrices(theta))

    def response(self, theta, s):
        """K(s) (nw, nu, ny) and the resolvent factors C(sI-A)^-1 (nw, nu, n), (sI-A)^-1 B (nw, n, ny)."""
        A, B, C, D = self.matrices(theta)
        n = self.n
        Z = s[:, None, None] * np.eye(n) - A
        Br = np.linalg.solve(Z, np.broadcast_to(B, (s.size, n, self.ny)))
        Cr = np.swapaxes(np.linalg.solve(np.swapaxes(Z, 1, 2), np.broadcast_to(C.T, (s.size, n, self.nu))), 1, 2)
        return Cr @ B + D, Cr, Br

    def d_response(self, Cr, Br):
        """dK/dtheta: (nw, nu*ny, ntheta), K flattened row-major."""
        nw, n, ny, nu = Cr.shape[0], self.n, self.ny, self.nu
        dA = np.einsum("wla,wbk->wlkab", Cr, Br).reshape(nw, nu * ny, n * n) @ self.E
        eye_y, eye_u = np.eye(ny), np.eye(nu)
        dB = np.einsum("wla,kc->wlkac", Cr, eye_y).reshape(nw, nu * ny, n * ny)
        dC = np.einsum("lm,wak->wlkma", eye_u, Br).reshape(nw, nu * ny, nu * n)
        dD = np.broadcast_to(np.eye(nu * ny), (nw, nu * ny, nu * ny))
        return np.concatenate([dA, dB, dC, dD], axis=2)

    def sensitivity_factors(self, Lft, Rgt, Cr, Br):
        r"""For the linear functional :math:`dK \mapsto L\,dK\,R` (``Lft`` (m, nu), ``Rgt`` (ny, m)):
        its value for each parameter, (ntheta, m, m)."""
        n = self.n
        X = Lft @ Cr                    # (m, n)
        Zr = Br @ Rgt                   # (n, m)
        FA = np.einsum("ia,bj->abij", X, Zr).reshape(n * n, X.shape[0], -1)
        FA = np.einsum("pij,pq->qij", FA, self.E) if n else FA[:0]
        FB = np.einsum("ia,kj->akij", X, Rgt).reshape(n * self.ny, X.shape[0], -1)
        FC = np.einsum("il,aj->laij", Lft, Zr).reshape(self.nu * n, X.shape[0], -1)
        FD = np.einsum("il,kj->lkij", Lft, Rgt).reshape(self.nu * self.ny, X.shape[0], -1)
        return np.concatenate([FA, FB, FC, FD], axis=0)


def _augmented_loop(P, K, nc, nr, nmeas, ncon):
    """The loop of ``P`` and ``K`` with an extra input ``v`` added to ``u`` and ``y`` as an extra
    output: inputs ``[w, v]``, outputs ``[z, y]``; its blocks are M, U (z from v), V (y from w)."""
    A, B, C, D = (np.asarray(X, float) for X in (P.A, P.B, P.C, P.D))
    Bw, Bu = B[:, :nr], B[:, nr:]
    Cz, Cy = C[:nc], C[nc:]
    Dz, Dy = D[:nc], D[nc:]
    Pa = ss(A, np.hstack([Bw, Bu, Bu]), np.vstack([Cz, Cy, Cy]),
            np.block([[Dz[:, :nr], Dz[:, nr:], Dz[:, nr:]], [Dy[:, :nr], Dy[:, nr:], Dy[:, nr:]],
                      [Dy[:, :nr], Dy[:, nr:], Dy[:, nr:]]]))
    return lft_lower(Pa, K, nmeas, ncon)


class _DGPoint:
    """Scalings of one frequency in the form lambda_max(Q) = bound^2,
    Q = R (M^H Dl M + j(GM - M^H G)) R, R = Dr^(-1/2)."""
    __slots__ = ("value", "Dl", "R", "G")

    def __init__(self, value, Dl, R, G):
        self.value, self.Dl, self.R, self.G = value, Dl, R, G

    def q(self, M):
        return self.R @ (M.conj().T @ self.Dl @ M + 1j * (self.G @ M - M.conj().T @ self.G.conj().T)) @ self.R


def _floored_scalings(Dl, Dr, S: BlockStructure, floor: float = 1e-8):
    """The D scalings with each block's eigenvalues raised to at least ``floor`` times the
    largest, in D_l and D_r alike (so still a valid pair).  Where a parameter barely matters
    its optimal scaling tends to zero, D_r^(-1/2) to 1e8 and beyond, and the scaled form Q
    to entries of 1e16 whose eigenvalues no longer have a correct digit."""
    Dl, Dr = Dl.copy(), Dr.copy()
    top = np.linalg.eigvalsh(Dr).max()
    for b, rs, cs in zip(S.blocks, S.row_slices, S.col_slices):
        ev, V = np.linalg.eigh(Dr[rs, rs])
        if ev.min() >= floor * top:
            continue
        if b.kind == "full":
            d = max(float(ev.mean()), floor * top)
            Dr[rs, rs] = d * np.eye(b.rows)
            Dl[cs, cs] = d * np.eye(b.cols)
        else:
            Dk = (V * np.maximum(ev, floor * top)) @ V.conj().T
            Dr[rs, rs] = Dk
            Dl[cs, cs] = Dk
    return Dl, Dr


def _dg_point(M, S: BlockStructure) -> _DGPoint:
    """D-G scalings of one frequency: the fast descent's, or the LMI's where those do not
    reproduce the fast value to 1e-3, their small D blocks floored (:func:`_floored_scalings`)
    unless that loses the 1e-3.  The value is sqrt(lambda_max(Q)) for the scalings kept, so
    certified by them."""
    for method in ("fast", "lmi"):
        u = mu_upper(M, S, method=method)
        if u.Dl is None:          # one full block: sigma_max is mu
            nr, nc = M.shape[1], M.shape[0]
            tries = [_DGPoint(u.value, np.eye(nc), np.eye(nr), np.zeros((nr, nc)))]
        else:
            tries = []
            for Dl, Dr in (_floored_scalings(u.Dl, u.Dr, S), (u.Dl, u.Dr)):
                ev, V = np.linalg.eigh(Dr)
                R = (V * ev ** -0.5) @ V.conj().T
                tries.append(_DGPoint(u.value, Dl, R, np.zeros_like(Dl) if u.G is None else u.G))
        for pt in tries:
            lam = np.linalg.eigvalsh(pt.q(M))[-1]
            if lam <= u.value ** 2 * (1.0 + 1e-3):
                pt.value = float(np.sqrt(max(lam, 0.0)))
                return pt
    raise SolverError(f"no consistent D-G scalings for a {M.shape[0]}x{M.shape[1]} loop matrix")


def _dg_points(Ms, S, old=None, reject_at=np.inf):
    """Scalings of every frequency.  With ``old`` (the scalings of the previous controller):
    the old scalings' values are upper bounds; new scalings are computed from the largest of
    them down until the next cannot raise the peak (the same rule as :func:`_dg_peak`).
    Returns None as soon as one frequency's bound reaches ``reject_at``."""
    if old is None:
        return [_dg_point(M, S) for M in Ms]
    pts = []
    for M, o in zip(Ms, old):
        lam = np.linalg.eigvalsh(o.q(M))[-1]
        pts.append(_DGPoint(float(np.sqrt(max(lam, 0.0))), o.Dl, o.R, o.G))
    best = 0.0
    for k in np.argsort([-p.value for p in pts]):
        if pts[k].value <= best:
            break
        pts[k] = _dg_point(Ms[k], S)
        best = max(best, pts[k].value)
        if best >= reject_at:
            return None
    return pts


def _refine_step(modal, theta, pts, M, U, V, rho, w, band=0.01, gap=0.02, spread=120):
    """Trust-region model step: minimise max over the active frequencies of the linearised
    lambda_max of Q (on its top eigenspace), with every parameter moving at most ``rho`` of
    its size and K(jw) at most ``rho`` of its norm at the active frequencies and at ``spread``
    frequencies spread evenly in log over the grid ``w``.  Returns the step (in units of
    ``modal.scale``) and the predicted peak of lambda_max, or None."""
    import cvxpy as cp
    Q = np.array([p.q(m) for p, m in zip(pts, M)])
    lam, Y = np.linalg.eigh(Q)
    top = lam[:, -1]
    peak = top.max()
    # the local maxima within the band and their neighbours: an equalised bound has hundreds
    # of points within it, but between its maxima they add nothing the maxima do not say
    near = top > peak * (1.0 - 2.0 * band)
    idx = [i for i in _local_maxima(top, top.size) if near[i]]
    act = np.unique(np.clip(np.concatenate([np.asarray(idx, int) + k for k in (-1, 0, 1)]), 0, top.size - 1))
    act = act[near[act]]
    # K(jw) moves smoothly between grid points: its trust region on a log-even subset of the
    # grid (dense near the peaks) constrains the step as much, at a fraction of the cost
    # (on the distillation column's 527 frequencies, 0.3 s a solve instead of 1.8 s); the
    # controller's response is needed there and at the active frequencies only
    lw = np.log(w)
    keep = np.union1d(act, np.abs(lw[:, None] - np.linspace(lw[0], lw[-1], spread)[None, :]).argmin(axis=0))
    Kw, Cr, Br = modal.response(theta, 1j * w[keep])
    pos = {int(i): j for j, i in enumerate(keep)}
    nt = theta.size
    d = cp.Variable(nt)
    tau = cp.Variable()
    lin_rows, lin_rhs, lmis = [], [], []
    for k in act:
        sel = lam[k] > lam[k, -1] * (1.0 - gap)
        Yk = Y[k][:, sel]
        p = pts[k]
        Lft = Yk.conj().T @ p.R @ (M[k].conj().T @ p.Dl + 1j * p.G) @ U[k]
        Rgt = V[k] @ p.R @ Yk
        F = modal.sensitivity_factors(Lft, Rgt, Cr[pos[k]], Br[pos[k]]) * modal.scale[:, None, None]
        H = F + np.conj(np.swapaxes(F, 1, 2))
        m = Yk.shape[1]
        if m == 1:
            lin_rows.append(np.real(H[:, 0, 0]))
            lin_rhs.append(lam[k][sel][0])
        else:
            Hr = np.real(H).reshape(nt, m * m).T
            Hi = np.imag(H).reshape(nt, m * m).T
            Xr = cp.reshape(Hr @ d, (m, m), order="C") + np.diag(lam[k][sel])
            Xi = cp.reshape(Hi @ d, (m, m), order="C")
            big = cp.bmat([[Xr, -Xi], [Xi, Xr]])
            lmis.append(tau * np.eye(2 * m) - 0.5 * (big + big.T) >> 0)
    cons = list(lmis)
    if lin_rows:
        cons.append(np.array(lin_rhs) + np.array(lin_rows) @ d <= tau)
    J = modal.d_response(Cr, Br) * modal.scale[None, None, :]
    Kn = np.linalg.norm(Kw.reshape(Kw.shape[0], -1), axis=1)
    J = J / np.maximum(Kn, 1e-300)[:, None, None]
    nk = J.shape[1]
    Jr = np.real(J).reshape(-1, nt)
    Ji = np.imag(J).reshape(-1, nt)
    stacked = cp.reshape(cp.hstack([Jr @ d, Ji @ d]), (2 * nk, J.shape[0]), order="F")
    cons += [cp.abs(d) <= rho, cp.norm(stacked, 2, axis=0) <= rho]
    prob = cp.Problem(cp.Minimize(tau), cons)
    # a model step needs no more than a few digits (every step is checked on the true bound);
    # where Clarabel's factorisation fails, ten times its default regularisation nearly always
    # does it, and SCS, the last resort, is capped (uncapped it took 37 s for a step Clarabel
    # solves in 0.7 s)
    clarabel = {"tol_feas": 1e-6, "tol_gap_abs": 1e-6, "tol_gap_rel": 1e-6, "reduced_tol_feas": 1e-3,
                "reduced_tol_gap_abs": 1e-3, "reduced_tol_gap_rel": 1e-3}
    for solver, opts in ((cp.CLARABEL, clarabel),
                         (cp.CLARABEL, {**clarabel, "static_regularization_constant": 1e-7}),
                         (cp.SCS, {"max_iters": 2500})):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")      # "solution may be inaccurate": the step is checked anyway
                prob.solve(solver=solver, **opts)
        except (cp.error.SolverError, ValueError, ArithmeticError):
            continue
        if d.value is not None and tau.value is not None:
            return np.asarray(d.value, float), float(tau.value), float(peak)
    return None


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
    fine grid of the controller given, each candidate is also evaluated
    halfway between its four largest local maxima and their neighbours (a
    probe above the old peak rejects the step and joins the grid), every
    ``regrid_every`` accepted steps the grid is refined around the ten largest
    local maxima (no new point closer than 0.001 % to one of the grid, and a
    new point starts from the scalings of its nearest neighbour, which bound
    it from above, so that only the points that could be the largest need
    scalings of their own), and when the fine grid of the final analysis finds a peak
    the refinement grid missed (by more than 0.01 %), its frequencies join the
    grid and the descent goes on for ``regrid_every`` more steps (at most three
    times).

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
    the default D-K controller's 1.0501 to 0.9943, with the same 18 states.

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
    Two steps on the first D-K controller (the H-infinity one) of the two-mass problem at
    0.043 m (about 10 s):

    >>> from mutext.examples import two_mass_uncertain as tmu
    >>> P = tmu.plant(0.043)
    >>> dkr = dk_iteration(P, tmu.structure(), 1, 1, max_iter=1)
    >>> ref = refine_controller(P, tmu.structure(), dkr.K, 1, 1, max_steps=2)
    >>> bool(ref.mu_upper_dg <= dkr.mu_upper_dg + 1e-9), ref.K.nstates == dkr.K.nstates
    (True, True)
    """
    t0 = time.perf_counter()
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
    nc, nr = S.ncols, S.nrows
    CL0 = lft_lower(P, K, nmeas, ncon)
    cl_poles = np.linalg.eigvals(np.asarray(CL0.A, float)) if CL0.nstates else np.zeros(0)
    if cl_poles.size and cl_poles.real.max() >= 0:
        raise ModelError(f"K does not stabilise P (closed-loop pole with real part {cl_poles.real.max():.3g})")
    modal = _Modal(K)
    theta = modal.theta.copy()
    if omega is None:
        w = np.unique(np.concatenate([default_grid(CL0, n=200, decades=1.5), _default_dk_grid(P, 80)]))
    else:
        w = np.unique(np.asarray(omega, float).ravel())
        if w.size == 0 or not (np.all(np.isfinite(w)) and np.all(w > 0)):
            raise ModelError("the frequency grid omega must hold positive, finite frequencies (rad/s)")
    ppoles = np.linalg.eigvals(np.asarray(P.A, float)) if P.nstates else np.zeros(0)
    light = np.abs(ppoles[np.abs(ppoles.real) < 1e-3 * np.abs(ppoles)].imag)

    def usable(w):
        return w[np.min(np.abs(w[:, None] - light[None, :]), axis=1) > 1e-3 * w] if light.size else w

    def new_points(wn, w):
        """The frequencies ``wn`` not within 0.001 % of a grid point: on a flat stretch of the
        bound, every point is a local maximum by a few digits, and probes between ever closer
        points would grow the grid (and the cost of a step) without finding anything."""
        wn = usable(np.setdiff1d(np.unique(wn), w))
        if not wn.size or w.size < 2:
            return wn
        lw = np.log(w)
        i = np.clip(np.searchsorted(lw, np.log(wn)), 1, lw.size - 1)
        gap = np.minimum(np.abs(np.log(wn) - lw[i - 1]), np.abs(np.log(wn) - lw[i]))
        return wn[gap > 1e-5]

    def evaluate(theta, w):
        Kt = modal.ss(theta)
        CLa = _augmented_loop(P, Kt, nc, nr, nmeas, ncon)
        poles = np.linalg.eigvals(np.asarray(CLa.A, float)) if CLa.nstates else np.zeros(0)
        stable = not poles.size or poles.real.max() < 0
        F = np.moveaxis(freqresp(CLa, w), -1, 0)
        return stable, F[:, :nc, :nr], F[:, :nc, nr:], F[:, nc:, :nr]

    def at(th, wp, near=None):
        """(M, U, V, scalings) of the loop with parameters ``th`` at the frequencies ``wp``.
        With ``near`` (a grid and its scalings), each frequency starts from the scalings of
        the nearest grid point, whose values bound it from above, and only those that could
        be the largest get their own (as in :func:`_dg_points`): a probe then costs one
        eigenvalue problem instead of a descent, and no value exceeds the largest exact one."""
        _, Mp, Up, Vp = evaluate(th, wp)
        if near is None or not wp.size:
            return Mp, Up, Vp, _dg_points(Mp, S)
        wg, pg = near
        j = np.abs(np.log(wp)[:, None] - np.log(wg)[None, :]).argmin(axis=1)
        return Mp, Up, Vp, _dg_points(Mp, S, [pg[k] for k in j])

    def probes(w, pts):
        """Frequencies halfway (in log) between the largest local maxima and their neighbours."""
        idx = _local_maxima([p.value for p in pts], 4)
        wp = [np.sqrt(w[i] * w[j]) for i in idx for j in (i - 1, i + 1) if 0 <= j < w.size]
        return new_points(np.asarray(wp), w) if wp else np.zeros(0)

    def merge(w, data, wp, extra):
        """The grid and its data with the frequencies ``wp`` and their data added, in order."""
        order = np.argsort(np.concatenate([w, wp]))
        M, U, V, pts = data
        Mp, Up, Vp, pp = extra
        out = [np.concatenate([a, b])[order] for a, b in ((w, wp), (M, Mp), (U, Up), (V, Vp))]
        allpts = list(pts) + list(pp)
        return out[0], out[1], out[2], out[3], [allpts[i] for i in order]

    def analysed(Kx, part):
        CLx = lft_lower(P, Kx, nmeas, ncon)
        rep = None if progress is None else (lambda stage, f: progress(stage, part[0] + (part[1] - part[0]) * f))
        return CLx, _final_analysis(CLx, S, _default_dk_grid(P, 80), 200, True, report=rep)

    # the controller given, on the fine grid of the final analysis: its frequencies join the
    # refinement grid (they hold the fine points around its peaks), and the result is compared
    # with it on that same grid at the end, so that it is never worse there
    CLg, fin_g = analysed(K, (0.0, 0.05))
    w = usable(np.unique(np.concatenate([w, fin_g[0].omega, fin_g[4]])))
    M, U, V, pts = at(theta, w)
    start = max(p.value for p in pts)
    history, notes = [], []
    rho, accepted, step, timed_out, limit = 1e-3, 0, 0, False, max_steps
    _print(out, f"{'step':>4} {'mu D-G (grid)':>14} {'model':>9} {'rho':>9} {'':>8} {'grid':>5} {'seconds':>8}")
    for check in range(4):
        with blas_single_thread():
            while step < limit:
                if time_limit is not None and time.perf_counter() - t0 > time_limit:
                    notes.append(f"refine: time limit of {time_limit:g} s reached after {step} steps")
                    timed_out = True
                    break
                step += 1
                if progress is not None:
                    progress(f"refine step {step}/{limit}: mu D-G {max(p.value for p in pts):.5f}, "
                             f"{w.size} frequencies", 0.05 + 0.88 * min(step - 1, max_steps) / max_steps)
                ti = time.perf_counter()
                peak = max(p.value for p in pts)
                res = _refine_step(modal, theta, pts, M, U, V, rho, w)
                ok = missed = False
                model = float("nan")
                if res is not None:
                    dstep, tau, lam_peak = res
                    model = float(np.sqrt(max(tau, 0.0)))
                    pred = lam_peak - tau
                    if pred > 1e-12 * lam_peak:
                        cand = theta + modal.scale * dstep
                        st, Mn, Un, Vn = evaluate(cand, w)
                        if st:
                            new = _dg_points(Mn, S, pts, reject_at=peak * (1.0 - 1e-9))
                            vn = np.inf if new is None else max(p.value for p in new)
                            if vn < peak * (1.0 - 1e-9):
                                # a step may push a narrow peak up between grid points: probe
                                # between the largest local maxima and their neighbours
                                wp = probes(w, new)
                                probed = at(cand, wp, (w, new)) if wp.size else None
                                if probed and max(p.value for p in probed[3]) >= peak * (1.0 - 1e-9):
                                    # rejected, and the grid keeps the probes (with this loop's data)
                                    w, M, U, V, pts = merge(w, (M, U, V, pts), wp, at(theta, wp, (w, pts)))
                                    missed = True
                                else:
                                    ok = True
                                    ratio = (peak ** 2 - vn ** 2) / pred
                                    theta, M, U, V, pts = cand, Mn, Un, Vn, new
                                    if probed:
                                        # the grid keeps the probes near the new peak
                                        near = np.flatnonzero([p.value >= 0.98 * vn for p in probed[3]])
                                        if near.size:
                                            w, M, U, V, pts = merge(w, (M, U, V, pts), wp[near],
                                                                    tuple(x[near] for x in probed[:3])
                                                                    + ([probed[3][i] for i in near],))
                                    rho = min(2.0 * rho, 0.2) if ratio > 0.5 else (rho / 2.0 if ratio < 0.1 else rho)
                if not ok:
                    rho /= 2.0 if missed else 4.0
                else:
                    accepted += 1
                mu_now = max(p.value for p in pts)
                history.append({"step": step, "mu_dg": mu_now, "model": model, "rho": rho, "accepted": ok,
                                "grid_points": int(w.size), "seconds": time.perf_counter() - ti,
                                "round": check})
                _print(out, f"{step:>4} {mu_now:>14.6f} {model:>9.5f} {rho:>9.2e} "
                            f"{'accepted' if ok else 'rejected':>8} {w.size:>5} {time.perf_counter() - ti:>8.2f}")
                if ok and accepted % regrid_every == 0:
                    extra = _around_peaks(w, np.array([p.value for p in pts]), 10, 6)
                    wn = new_points(np.concatenate(extra), w) if extra else np.zeros(0)
                    if wn.size:
                        w, M, U, V, pts = merge(w, (M, U, V, pts), wn, at(theta, wn, (w, pts)))
                if rho < 1e-7:
                    notes.append(f"refine: stopped at step {step}, no model step lowers the bound "
                                 f"(trust region {rho:.1e})")
                    break
        Kr = modal.ss(theta)
        f = 0.05 + 0.88 * min(step, max_steps) / max_steps     # the bar holds while the fine grid is checked
        CL, (final, low, low_c, mu_dg, extra) = analysed(Kr, (f, f))
        on_grid = max(p.value for p in pts)
        if timed_out or check == 3 or mu_dg <= on_grid * (1.0 + 1e-4):
            break
        # the fine grid found a peak the refinement grid missed by more than 0.01 % (a step
        # raised the bound between its points, or beyond its ends): its frequencies join the
        # grid and the descent goes on for ``regrid_every`` more steps, from a trust region
        # that can still move
        notes.append(f"refine: after step {step} the fine grid found {mu_dg:.5f} where the refinement grid "
                     f"had {on_grid:.5f}; its {final.omega.size} frequencies were added and up to "
                     f"{regrid_every} more steps follow")
        w = usable(np.unique(np.concatenate([w, final.omega, extra])))
        M, U, V, pts = at(theta, w)
        rho, limit = max(rho, 1e-4), step + regrid_every
    if accepted and fin_g[3] < mu_dg:
        notes.append(f"refine: on the final grid the refined loop ({mu_dg:.5f}) is not below the loop "
                     f"given ({fin_g[3]:.5f}): the controller given is returned")
        Kr, CL, (final, low, low_c, mu_dg, _) = K, CLg, fin_g
    cl_poles = np.linalg.eigvals(np.asarray(CL.A, float)) if CL.nstates else np.zeros(0)
    max_re = float(cl_poles.real.max()) if cl_poles.size else float("-inf")
    notes.append(f"refine: {accepted} of {len(history)} steps accepted; D-G bound on the refinement grid "
                 f"{start:.5f} -> {max(p.value for p in pts):.5f}, on the final grid {mu_dg:.5f}")
    _print(out, f"refined: fine grid: {low:.4f} <= mu <= {mu_dg:.4f} (D-G), {final.peak_upper:.4f} complex; "
                f"controller order {Kr.nstates}; {time.perf_counter() - t0:.1f} s")
    return DKResult(K=Kr, CL=CL, mu_upper=float(final.peak_upper), mu_upper_dg=mu_dg, mu_lower=low,
                    mu_lower_complex=low_c, peak_frequency=float(final.peak_frequency), history=history,
                    sweep=final, fits=[], seconds=time.perf_counter() - t0, best_iteration=0, notes=notes,
                    near_axis_poles=near_axis_poles(P), max_pole_real=max_re)
