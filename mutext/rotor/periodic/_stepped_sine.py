r"""The analyzer in software: :func:`stepped_sine` integrates the reduced time-periodic rotor
in time (classical Runge-Kutta, the breathing laws evaluated at every stage), an independent
check of the harmonic balance.
"""
from __future__ import annotations

import time
from typing import Sequence

import numpy as np

from ...errors import ModelError
from ...lti import blas_single_thread
from ._window import ANALYZER, _settle
from ._balance import _freqs
from ._model import PeriodicRotor, periodic_rotor


def _rk4_propagators(pr: PeriodicRotor, P: int, h: float, input_index: int):
    """Per phase step j: z+ = F_j z + g_j @ [u(t), u(t+h/2), u(t+h)] for RK4 on the modal model."""
    r = pr.n
    eps = 1e-9 * h        # the Gasch switch falls on step boundaries: evaluate inside the step
    t = np.arange(P) * h
    stages = np.stack([t + eps, t + 0.5 * h, t + h - eps], axis=1)      # (P, 3)
    K = pr.stiffness_at(pr.speed * stages.ravel()).reshape(P, 3, r, r)
    Mi = np.linalg.inv(pr.M)          # the identity on a mass-orthonormal basis
    A = np.zeros((P, 3, 2 * r, 2 * r))
    A[:, :, :r, r:] = np.eye(r)
    A[:, :, r:, :r] = -Mi @ K
    A[:, :, r:, r:] = -Mi @ pr.D
    b = np.zeros(2 * r)
    b[r:] = Mi @ pr.B[:, input_index]
    I = np.eye(2 * r)

    def step(z, b0, bh, b1):
        A0, Ah, A1 = A[:, 0], A[:, 1], A[:, 2]
        k1 = A0 @ z + b0
        k2 = Ah @ (z + 0.5 * h * k1) + bh
        k3 = Ah @ (z + 0.5 * h * k2) + bh
        k4 = A1 @ (z + h * k3) + b1
        return z + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)

    zero_b = np.zeros((P, 2 * r, 1))
    F = step(np.broadcast_to(I, (P, 2 * r, 2 * r)), 0.0, 0.0, 0.0)
    zz = np.zeros((P, 2 * r, 1))
    bb = np.broadcast_to(b[:, None], (P, 2 * r, 1))
    g = np.concatenate([step(zz, bb, zero_b, zero_b), step(zz, zero_b, bb, zero_b),
                        step(zz, zero_b, zero_b, bb)], axis=2)         # (P, 2r, 3)
    return F, g


def _port_index(names, name, kind: str) -> int:
    """Position of port ``name`` among ``names`` (the first when ``None``), or a named error."""
    if name is None:
        return 0
    if name not in names:
        raise ModelError(f"no {kind} port '{name}' in this rotor; its {kind}s are {', '.join(names)}")
    return list(names).index(name)


def stepped_sine(model, freqs_hz, *, in_port: str | None = None, out_port: str | None = None,
                 amplitude: float = ANALYZER["amplitude"], revolutions: int = ANALYZER["revolutions"],
                 settle_s: float = ANALYZER["settle_s"], excitation_phase: float = 0.0,
                 steps_per_rev: int | None = None, cutoff_hz: float = 1500.0, progress=None,
                 orders: Sequence[int] = ()) -> dict:
    r"""Brute-force stepped-sine measurement by time integration (the analyzer, in software).

    Each frequency starts from rest with the rotor at angle zero, is driven
    by :math:`a\cos(\omega t + \varphi)` for ``settle_s`` (rounded to whole
    integration steps) and then correlated with the excitation over
    ``revolutions`` turns, exactly as :func:`analyzer_frf` assumes, except
    that nothing is assumed about the steady state: the residual transient
    of a lightly damped mode after the settling time is part of the result.
    The equations are integrated on the modal basis of
    :meth:`PeriodicRotor.reduce` (``cutoff_hz`` if ``model`` is not reduced)
    by the classical Runge-Kutta method with ``steps_per_rev`` steps per turn
    (default: the stability limit of the stiffest basis vector with a margin,
    and at least 40 steps per period of the response); the breathing laws are evaluated at every stage, so the check does
    not rely on their Fourier series.  ``orders`` adds the correlations at
    the combination frequencies :math:`\omega + k\Omega` (the independent
    check of :func:`analyzer_combination`).

    Parameters
    ----------
    model : PeriodicRotor or Rotor
        The time-periodic model (full or reduced), or a rotor with a turning crack
        (then built with :func:`periodic_rotor`).
    freqs_hz : array_like
        Excitation frequencies [Hz] (positive).

    in_port, out_port : str, optional
        The excited input and the measured output (default: the first of each).
    amplitude : float, optional
        Excitation amplitude (input unit, e.g. A).
    revolutions : int, optional
        Turns of the correlation window.
    settle_s : float, optional
        Settling time before the window [s].
    excitation_phase : float, optional
        Phase :math:`\varphi` [rad] of the excitation :math:`a\cos(\omega t + \varphi)`
        with the rotor at its angle zero at t = 0.

    steps_per_rev : int, optional
        Runge-Kutta steps per revolution (default: from the stability limit).
    cutoff_hz : float, optional
        Cutoff [Hz] of the reduction when ``model`` is not reduced.
    progress : callable, optional
        Called with the fraction of the work done (0..1).
    orders : sequence of int, optional
        Orders k of the combination frequencies also correlated.

    Returns
    -------
    dict
        ``freqs_hz``, ``H`` (complex, output unit per input unit), ``steps_per_rev``,
        ``settle_s`` (as used), ``seconds``, ``n_modes``; with ``orders``,
        ``H_orders`` = ``{k: response at f + k F per input unit}``.
    """
    t0 = time.perf_counter()
    pr = model if isinstance(model, PeriodicRotor) else periodic_rotor(model)
    ii = _port_index(pr.inputs, in_port, "input")
    oi = _port_index(pr.outputs, out_port, "output")
    f = _freqs(freqs_hz)
    if pr.basis is None:
        pr = pr.reduce(cutoff_hz)
    if not (np.isfinite(amplitude) and amplitude > 0):
        raise ModelError(f"amplitude must be positive, got {amplitude!r}")
    t_s, _ = _settle(pr, settle_s, revolutions)
    # the stiffest state, not the revolution average: an open crack only removes stiffness (the
    # breathing weights lie in [0, 1]), so the closed crack, K_healthy, bounds K(t) from above; with
    # the mean, a switching (Gasch) crack with both compliances drives RK4 unstable while it is closed
    w_max = float(np.sqrt(np.max(np.linalg.eigvalsh(pr.K_healthy))))
    if steps_per_rev is None:
        # RK4 is stable for h w < 2.8 on the imaginary axis: the stiffest Ritz shape sets the step;
        # the swept response itself gets at least 40 steps per period
        steps_per_rev = max(200, int(np.ceil(w_max * pr.period / 2.5)),
                            int(np.ceil(40 * (f.max() + 3 * pr.speed / (2 * np.pi)) * pr.period)))
    P = int(steps_per_rev)
    if P < 8:
        raise ModelError(f"steps_per_rev must be at least 8, got {steps_per_rev!r}")
    h = pr.period / P
    n_settle = int(round(t_s / h))
    n_rec = revolutions * P
    F, g = _rk4_propagators(pr, P, h, ii)
    r = pr.n
    w = 2 * np.pi * f
    Z = np.zeros((2 * r, f.size))
    c_out = np.zeros(2 * r)
    c_out[:r] = pr.Cy[oi]
    acc = np.zeros(f.size, complex)
    korders = [int(k) for k in orders]
    acc_k = {k: np.zeros(f.size, complex) for k in korders}
    ph = excitation_phase
    total = n_settle + n_rec
    report = max(1, total // 20)
    with blas_single_thread():
        for step in range(total):
            j = step % P
            tn = step * h
            U = amplitude * np.cos(np.outer([tn, tn + 0.5 * h, tn + h], w) + ph)
            Z = F[j] @ Z + g[j] @ U
            if step + 1 > n_settle:
                y = c_out @ Z
                tt = (step + 1) * h
                acc += y * np.exp(-1j * (w * tt + ph))
                for k in korders:
                    acc_k[k] += y * np.exp(-1j * ((w + k * pr.speed) * tt + ph))
            if progress is not None and step % report == 0:
                progress(step / total)
    # rectangle rule over whole periods: samples at t_s + h, ..., t_s + T (periodic integrand)
    H = 2.0 * acc / (amplitude * n_rec)
    extra = {"H_orders": {k: 2.0 * a / (amplitude * n_rec) for k, a in acc_k.items()}} if korders else {}
    return {**extra, "freqs_hz": f, "H": H, "steps_per_rev": P, "settle_s": n_settle * h, "seconds":
            time.perf_counter() - t0, "n_modes": r, "input": pr.inputs[ii], "output": pr.outputs[oi],
            "reduction_error": pr.reduction_error}
