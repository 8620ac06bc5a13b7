r"""What the stepped-sine analyzer does with a time-periodic rotor's response: its settings, the settling
time and the correlation window (whole revolutions), and the response it reports at one order
(:func:`_correlated`), used by the analyzer (``_analyzer``), its automatic truncation (``_truncation``) and
the stepped-sine simulation (``_stepped_sine``).
"""
from __future__ import annotations

import numpy as np

from ...errors import ModelError
from ...response import FRFMatrix
from ._balance import HarmonicResponse
from ._model import PeriodicRotor

#: The thesis's sweep settings (sec. 4.3): 0.1 A, 40 revolutions per correlation, 700 ms settling.
ANALYZER = {"amplitude": 0.1, "revolutions": 40, "settle_s": 0.7}


def _window_average(nu, t_start, T):
    """(1/T) * integral of exp(j nu t) over [t_start, t_start + T]."""
    nu = np.asarray(nu, float)
    small = np.abs(nu * T) < 1e-9
    safe = np.where(small, 1.0, nu)
    val = np.exp(1j * safe * t_start) * (np.exp(1j * safe * T) - 1.0) / (1j * safe * T)
    return np.where(small, np.exp(1j * nu * t_start), val)


def _settle(pr: PeriodicRotor, settle_s: float, revolutions: int):
    if not (np.isfinite(settle_s) and settle_s >= 0):
        raise ModelError(f"settle_s must be a non-negative time [s], got {settle_s!r}")
    if isinstance(revolutions, bool) or not isinstance(revolutions, (int, np.integer)) or revolutions < 1:
        raise ModelError(f"revolutions must be a positive integer, got {revolutions!r}")
    if not pr.speed > 0:
        raise ModelError(f"{pr.name}: the analyzer correlates over whole revolutions; the rotor does not "
                         "turn (speed 0)")
    return float(settle_s), revolutions * pr.period


def _correlated(pr: PeriodicRotor, hr: HarmonicResponse, k: int, t_s: float, T: float,
                excitation_phase: float, descending: bool = False) -> FRFMatrix:
    r"""The analyzer's response at order ``k`` (module docstring): :math:`\hat H_k = H_k +
    e^{-2j\varphi}\sum_{k'}\overline{H_{k'}}\,\langle e^{-j(2\omega + (k+k')\Omega)t}\rangle` over
    the window :math:`[t_s, t_s + T]`, :math:`k'` over all the orders of ``hr``; ``k = 0`` is
    :math:`\hat H`.  The sum runs up the orders :math:`k'`, or down them with ``descending`` (the
    order :func:`analyzer_frf` has always summed in, kept for its results to the last bit)."""
    w = 2 * np.pi * hr.freqs_hz
    N = hr.harmonics
    H = hr(k).copy()
    for kp in (range(N, -N - 1, -1) if descending else range(-N, N + 1)):
        avg = _window_average(-(2 * w + (k + kp) * pr.speed), t_s, T)
        H += np.exp(-2j * excitation_phase) * np.conj(hr(kp)) * avg
    return FRFMatrix(hr.freqs_hz, H, list(pr.inputs), list(pr.outputs), pr.speed, dict(pr.ports))
