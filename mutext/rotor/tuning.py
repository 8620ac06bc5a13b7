r"""Tuning model parameters to measured frequency responses (model updating).

The thesis tuned the density and the disk mass of its rotor model by hand
until the first two resonances of the sine sweeps matched.  :func:`tune`
does the same systematically: it fits any set of the model's symbolic
parameters (a station-table entry, a bearing stiffness, the exciter's force
per ampere, a crack depth ratio, ...) to measured FRFs
(:class:`mutext.rig.FRF`, several channels) by nonlinear least squares,
solved by IPOPT through CasADi, with exact first derivatives.

The model response and its exact parameter sensitivities are derived in
:mod:`mutext.rotor.sensitivity` (:func:`frf_sensitivity` and
:func:`model_response`, re-exported here).

Objective
---------
The residual of channel :math:`c` at frequency :math:`\omega_i` is the
complex logarithm of the model/measurement ratio,

.. math::
    r_{ci} = \ln\frac{H_c(j\omega_i; p)}{\hat H_c(j\omega_i)}
      = \ln\frac{|H_c|}{|\hat H_c|} + j\,\angle\frac{H_c}{\hat H_c},
    \qquad f(p) = \tfrac12\sum_{c,i} w_c\left[(\mathrm{Re}\,r_{ci})^2 + (\mathrm{Im}\,r_{ci})^2\right],

i.e. the log-magnitude error (nepers; :math:`\times 20/\ln 10` for dB) and the
phase error (rad) weighted equally.  Taking the logarithm of the *ratio*
keeps the phase difference in :math:`(-\pi, \pi]` whatever the phase
unwrapping of model and data.  The relative measurement noise of a sine
sweep (:class:`mutext.rig.Noise`) is homoscedastic in this metric, and
resonances and anti-resonances weigh alike (on logarithmic least squares
for FRFs: Pintelon and Schoukens 2012).

The optimisation variables are the parameters divided by their start values
(*normalised* parameters, all of order one), with bounds.  IPOPT (Wächter and
Biegler 2006) gets the exact gradient :math:`J^Tr` and the Gauss-Newton
Hessian :math:`J^TJ` (:math:`J = \partial r/\partial\theta`, the standard
Hessian model for least squares).

Implementation
--------------
One idea a module:

* :mod:`mutext.rotor.frf_channels`: the measured FRFs as channels of the
  model (input column, output DOF, speed; :func:`select_points`);
* :mod:`mutext.rotor.sensitivity`: :math:`H` and :math:`\partial H/\partial p`
  with one complex LU factorisation per frequency, reused for the adjoint;
* :mod:`mutext.rotor._tune_objective`: the fitted unknowns (scaling, bounds,
  ties), the fitted channels and the log residual with its Jacobian;
* :mod:`mutext.rotor._ipopt`: the IPOPT driver (the residual and its
  Jacobian as ``casadi.Callback`` objects in a ``casadi.nlpsol`` problem);
* this module: :func:`tune`, which chains them, and the statistics of
  :class:`TuneResult`.

CasADi supplies the model (the compiled functions :math:`M(p), \dots, B(p)`
and their exact symbolic Jacobians) and the optimiser.  A CasADi
expression graph of the solve itself (the real :math:`2n\times 2n` block
system, mapped over the frequencies, differentiated algorithmically) gives
the same numbers -- the tests compare the two on a small model -- but on the
thesis rotor it is one to two orders of magnitude slower: modal damping makes
the damping matrix dense, so the sparse solvers gain nothing, and the real
block system has eight times the flops of the complex one.  With the
callback, a fit of two or three parameters to two 411-point channels takes
a few seconds.

Uncertainty
-----------
At the optimum :math:`\hat\theta` with :math:`N` real residuals and
:math:`n` parameters (the usual linearised least-squares estimate: Friswell
and Mottershead 1995; Pintelon and Schoukens 2012),

.. math::
    \hat\sigma^2 = \frac{\|r\|^2}{N - n},\qquad
    \mathrm{cov}(\hat\theta) \approx \hat\sigma^2 (J^TJ)^{-1},

reported as standard uncertainties of the parameters (SI) and their
correlation matrix.  These are *statistical* uncertainties: they assume the
model structure is right and the residual is noise; a model error shows up
as a large residual and structured (not white) residuals over frequency.

References
----------
.. [FM95] M. I. Friswell and J. E. Mottershead, *Finite Element Model
   Updating in Structural Dynamics*, Kluwer, 1995 (sensitivity-based
   penalty methods, updating with frequency-response data, statistics of
   the estimates).
.. [WB06] A. Wächter and L. T. Biegler, "On the implementation of an
   interior-point filter line-search algorithm for large-scale nonlinear
   programming", *Math. Programming* 106 (2006) 25-57 (IPOPT).
.. [CasADi] J. A. E. Andersson, J. Gillis, G. Horn, J. B. Rawlings and M.
   Diehl, "CasADi: a software framework for nonlinear optimization and
   optimal control", *Math. Programming Computation* 11 (2019) 1-36.
.. [PS12] R. Pintelon and J. Schoukens, *System Identification: A Frequency
   Domain Approach*, 2nd ed., Wiley-IEEE Press, 2012.
.. [Mad] R. J. Madden, *Identification of unmodeled dynamics in rotor systems
   using mu-synthesis approach*, M.S. thesis, Cleveland State University,
   ch. 4 (hand tuning of density and disk mass).
"""
from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError, SolverError
from ..response import FRF
from ._ipopt import _SUCCESS, _LeastSquares
from ._tune_objective import _check_bound_keys, _entries, _fit_channels, _LogResidual, _Unknowns, _unknowns
from .frf_channels import _as_model, _Inputs, _lookup, select_points
from .sensitivity import FRFSensitivity, frf_sensitivity, model_response

__all__ = ["TuneResult", "FRFSensitivity", "tune", "frf_sensitivity", "model_response",
           "select_points", "DB_PER_NEPER"]

#: dB per neper of log-magnitude: 20 / ln(10).
DB_PER_NEPER = 20.0 / math.log(10.0)


@dataclass
class TuneResult:
    r"""Result of :func:`tune`.

    Attributes
    ----------
    parameters : list of str
        Fitted quantities: a parameter name, or ``"a+b"`` for names tied
        together (then the value is that of the first name).
    values : dict
        Fitted value (SI) of each fitted quantity.
    start : dict
        Start values (SI).
    std : dict
        Standard uncertainty (SI), :math:`\hat\sigma\sqrt{[(J^TJ)^{-1}]_{kk}}`.
    units : dict
        SI unit of each fitted quantity.
    bounds : dict
        Bounds used (SI).
    covariance : ndarray (n, n)
        Covariance of the fitted values (SI).
    correlation : ndarray (n, n)
    member_values : dict
        Fitted value of every model parameter changed by the fit.
    parameter_vector : ndarray
        The full parameter vector of the model with the fitted values.
    residual_rms_db, residual_rms_deg : float
        RMS of the log-magnitude error [dB] and of the phase error [deg] at the optimum.
    start_rms_db, start_rms_deg : float
        The same at the start values.
    channel_rms : dict
        Per channel label: ``(rms dB, rms deg)`` at the optimum.
    sigma : float
        Estimated standard deviation of one real log residual (nepers / rad).
    n_points : int
        Complex data points fitted (all channels).
    status : str
        IPOPT's return status.
    iterations : int
    seconds : float
        Wall time of the solve (without building the problem).
    build_seconds : float
    history : list of float
        Objective at every IPOPT iteration.
    n_solves : int
        Complex LU factorisations of the dynamic stiffness performed.
    """
    parameters: list
    values: dict
    start: dict
    std: dict
    units: dict
    bounds: dict
    covariance: np.ndarray
    correlation: np.ndarray
    member_values: dict
    parameter_vector: np.ndarray
    residual_rms_db: float
    residual_rms_deg: float
    start_rms_db: float
    start_rms_deg: float
    channel_rms: dict
    sigma: float
    n_points: int
    status: str
    iterations: int
    seconds: float
    build_seconds: float
    history: list = field(default_factory=list)
    n_solves: int = 0

    def relative_std(self) -> dict:
        """Standard uncertainty relative to the fitted value."""
        return {k: (self.std[k] / abs(self.values[k]) if self.values[k] != 0 else float("inf"))
                for k in self.parameters}

    def summary(self) -> str:
        lines = [f"{'parameter':<24} {'start':>12} {'fitted':>12} {'std':>10} {'unit':<8}"]
        for k in self.parameters:
            lines.append(f"{k:<24} {self.start[k]:>12.5g} {self.values[k]:>12.5g} {self.std[k]:>10.2g} "
                         f"{self.units[k]:<8}")
        lines.append(f"residual RMS: {self.residual_rms_db:.3f} dB, {self.residual_rms_deg:.3f} deg "
                     f"(start: {self.start_rms_db:.3f} dB, {self.start_rms_deg:.3f} deg); "
                     f"{self.n_points} points")
        lines.append(f"IPOPT: {self.status}, {self.iterations} iterations, {self.seconds:.2f} s")
        if len(self.parameters) > 1:
            lines.append("correlation:")
            for k, row in zip(self.parameters, self.correlation):
                lines.append(f"  {k:<22} " + " ".join(f"{x:+.3f}" for x in row))
        return "\n".join(lines)

    __str__ = summary


def tune(model, frfs, parameters, bounds: Mapping | None = None, *, start: Mapping | None = None,
         values=None, band_hz=None, max_points: int | None = None, weights=None, verbose: bool = False,
         max_iter: int = 100, tol: float = 1e-8, hessian: str = "gauss-newton",
         ipopt_options: Mapping | None = None,
         progress: Callable[[str, float], None] | None = None) -> TuneResult:
    r"""Fit model parameters to measured FRFs by IPOPT (see the module docstring).

    Parameters
    ----------
    model : Rotor, Structure or path of a model file
        The model with symbolic parameters.
    frfs : mutext.rig.FRF or sequence of them
        Measured channels (SI, with input/output stations and quantities; a
        ``current`` input needs an exciter at that station, a ``force`` input
        is a unit force on the station's x DOF).  ``speed_hz`` of an FRF sets
        the spin speed of its channel (default: the model's speed).
        ``input_direction`` / ``output_direction`` = ``"y"``
        select the y direction.
    parameters : sequence
        Names of the parameters to fit (``model.parameter_names``, e.g.
        ``"rho"``, ``"disk16.m"``, ``"bearing2.k"``, ``"exciter12.ki"``,
        ``"crack15.depth_ratio"``).  A tuple of names is fitted as one
        quantity: the names keep the ratios of their start values (e.g. two
        identical bearings ``("bearing2.k", "bearing29.k")``).
    bounds : mapping name -> (lo, hi), optional
        SI bounds (for a tuple, keyed by its first name or by the tuple).
        Default: a decade either side of the start value; ``[0, 0.5]`` for a
        crack depth ratio.  A parameter starting at 0 needs bounds.
    start : mapping name -> value, optional
        Start values (SI); default the model's values.
    values : mapping or array, optional
        Values of the *other* parameters (default nominal).
    band_hz : (float, float), optional
        Fit only the frequencies in this band [Hz] (e.g. the thesis band
        ``mutext.rig.THESIS_ANALYSIS_BAND_HZ``).
    max_points : int, optional
        Use at most about this many frequencies per channel
        (:func:`select_points`); default all.
    weights : sequence of float, optional
        Weight of each channel in the objective (default 1).
    verbose : bool
        Print the objective at every iteration (to stdout; for a program,
        ``progress`` is the quiet alternative).
    max_iter : int
        IPOPT iteration limit.
    tol : float
        IPOPT convergence tolerance (on the scaled optimality error).  The
        objective is only computed to about 1e-12 relative (one LU solve per
        frequency), so near the optimum IPOPT's line search can stall on
        round-off: the options ``acceptable_tol = max(tol, 1e-6)``,
        ``acceptable_iter = 2`` (stop as "Solved_To_Acceptable_Level") and
        ``accept_after_max_steps = 5`` (accept a trial point after five
        backtracking steps) are set unless ``ipopt_options`` overrides them.
    hessian : {"gauss-newton", "limited-memory"}
        Hessian model given to IPOPT.
    ipopt_options : mapping, optional
        Extra IPOPT options (``{"max_cpu_time": 60}``, ...).
    progress : callable(stage: str, fraction: float), optional
        Called at every IPOPT iteration with the iteration line (objective,
        RMS error, parameter values) and ``iteration / max_iter``, and once
        with fraction 1 at the end (e.g. :class:`mutext.progress.ProgressLine`).

    Returns
    -------
    TuneResult

    Raises
    ------
    ModelError
        Unknown parameter (the message lists the valid names), a parameter
        given twice, bounds with lo > hi or a start outside them, an FRF
        without stations, a station not in the model, a current input where
        the model has no exciter, no frequency inside ``band_hz``, or fewer
        data than parameters.
    SolverError
        If IPOPT does not converge (the message gives IPOPT's return status).
    """
    t_build = time.perf_counter()
    model = _as_model(model)
    frfs = _checked_frfs(model, frfs)
    entries = _entries(model, parameters)
    v0 = _start_vector(model, values, start)
    bounds = dict(bounds or {})
    _check_bound_keys(model, bounds, entries)
    unknowns = _unknowns(model, entries, v0, bounds)
    inputs = _Inputs(model)
    chans, out_dofs = _fit_channels(model, frfs, inputs, band_hz, max_points, weights)
    n_pts = sum(c.freq_hz.size for c in chans)
    if 2 * n_pts <= len(entries):
        raise ModelError(f"{n_pts} data points cannot determine {len(entries)} parameters")
    objective = _LogResidual(model, unknowns, v0, chans, inputs, out_dofs)
    history: list[float] = []
    on_iterate = _iteration_reporter(history, unknowns, objective.n_residuals, max_iter, verbose, progress)
    problem = _LeastSquares(objective, on_iterate, max_iter=max_iter, tol=tol, hessian=hessian,
                            ipopt_options=ipopt_options)
    build_seconds = time.perf_counter() - t_build

    t0 = time.perf_counter()
    theta, status, iters, r_start, fit = _solve(objective, problem, unknowns)
    seconds = time.perf_counter() - t0
    if progress is not None:
        progress(f"tune: {status}, {iters} iterations, {seconds:.1f} s", 1.0)
    return _tune_result(model, unknowns, objective, chans, theta, r_start, fit,
                        n_pts=n_pts, status=status, iterations=iters, seconds=seconds,
                        build_seconds=build_seconds, history=history)


def _checked_frfs(model, frfs) -> list:
    """The measured FRFs as a list (one FRF or a sequence), for a model :func:`tune` can fit."""
    from .lumped_elements import impedances
    if impedances(model):
        # the fitted responses are built from M, C, K; K(s) of the element would be left out silently
        raise ModelError(f"tune: {model.name} holds the impedance element '{impedances(model)[0].name}' "
                         "(a rational K(s), not part of M, C, K); tune the model without it")
    frfs = [frfs] if isinstance(frfs, FRF) else list(frfs)
    if not frfs:
        raise ModelError("tune: no FRFs given")
    return frfs


def _solve(objective, problem, unknowns):
    """IPOPT from the start values: ``(theta, status, iterations, start residuals, (rr, r, JJ))``,
    the last the objective's residuals and Gauss-Newton terms at the optimum."""
    from .analysis import blas_single_thread
    scale = unknowns.scale
    with blas_single_thread():
        _, r_start = objective.evaluate(unknowns.x0 / scale, False)
        theta, status, iters = problem.solve(unknowns.x0 / scale, unknowns.lo / scale, unknowns.hi / scale)
        if status not in _SUCCESS:
            raise SolverError(f"IPOPT did not converge: return status {status} after {iters} iterations "
                              f"(parameters {unknowns.names}; last values "
                              f"{dict(zip(unknowns.names, (scale * theta).tolist()))})")
        fit = objective.evaluate(theta, True)
    return theta, status, iters, r_start, fit


def _tune_result(model, unknowns, objective, chans, theta, r_start, fit, *, n_pts, status, iterations,
                 seconds, build_seconds, history) -> TuneResult:
    """The :class:`TuneResult` of the optimum ``theta`` (scaled unknowns)."""
    rr, r, JJ = fit
    scale = unknowns.scale
    xopt = scale * theta
    cov, corr, sd, sigma2 = _covariance(rr, JJ, scale)
    vfit = objective.full_vector(xopt)
    names = unknowns.names
    ch_rms, off = {}, 0
    for c in chans:
        ch_rms[c.label] = _rms(r[off:off + c.freq_hz.size])
        off += c.freq_hz.size
    (rms_db, rms_deg), (start_db, start_deg) = _rms(r), _rms(r_start)
    return TuneResult(
        parameters=names,
        values=dict(zip(names, xopt.tolist())),
        start=dict(zip(names, unknowns.x0.tolist())),
        std=dict(zip(names, sd.tolist())),
        units=dict(zip(names, unknowns.units)),
        bounds={k: (a, b) for k, a, b in zip(names, unknowns.lo.tolist(), unknowns.hi.tolist())},
        covariance=cov, correlation=corr,
        member_values={model.parameter_names[i]: float(vfit[i]) for i in unknowns.members},
        parameter_vector=vfit,
        residual_rms_db=rms_db, residual_rms_deg=rms_deg, start_rms_db=start_db, start_rms_deg=start_deg,
        channel_rms=ch_rms, sigma=math.sqrt(sigma2), n_points=n_pts, status=status, iterations=iterations,
        seconds=seconds, build_seconds=build_seconds, history=history, n_solves=objective.evaluator.n_solves)


def _start_vector(model, values, start):
    """The model's parameter vector at the start: ``values`` (default nominal), then ``start``."""
    v0 = model.values(values)
    if start:
        for k, x in start.items():
            v0[_lookup(model, k)] = float(x)
    return v0


def _iteration_reporter(history: list, unknowns: _Unknowns, n_residuals: int, max_iter: int, verbose: bool,
                        progress):
    """``on_iterate(objective, theta)`` for IPOPT: records the objective, prints and/or reports a line."""
    def on_iterate(f, theta):
        history.append(f)
        if not verbose and progress is None:
            return
        xs = unknowns.scale * theta
        rms = math.sqrt(2.0 * f / n_residuals)
        line = (f"iter {len(history) - 1:3d}  objective {f:.6e}  rms {rms * DB_PER_NEPER:.4f} dB / "
                f"{math.degrees(rms):.4f} deg  " + "  ".join(f"{k}={x:.6g}" for k, x in zip(unknowns.names, xs)))
        if verbose:
            print("  " + line, flush=True)
        if progress is not None:
            progress(f"tune: {line}", min((len(history) - 1) / max(int(max_iter), 1), 1.0))
    return on_iterate


def _covariance(rr, JJ, scale):
    r"""Linearised statistics at the optimum (module docstring, *Uncertainty*).

    Returns the SI covariance, the correlation, the standard uncertainties
    and :math:`\hat\sigma^2`.
    """
    n_res, n_unk = JJ.shape
    sigma2 = float(rr @ rr) / max(n_res - n_unk, 1)
    try:
        cov_theta = sigma2 * np.linalg.inv(JJ.T @ JJ)
    except np.linalg.LinAlgError:
        cov_theta = np.full((n_unk, n_unk), np.inf)
    cov = cov_theta * np.outer(scale, scale)
    sd = np.sqrt(np.clip(np.diag(cov), 0, None))
    with np.errstate(divide="ignore", invalid="ignore"):
        corr = cov / np.outer(sd, sd)
    return cov, corr, sd, sigma2


def _rms(r):
    """RMS log-magnitude error [dB] and phase error [deg] of complex log residuals ``r``."""
    return (float(np.sqrt(np.mean(r.real ** 2)) * DB_PER_NEPER), float(np.degrees(np.sqrt(np.mean(r.imag ** 2)))))
