r"""A measured FRF as the true system: its stable rational stand-in, the grid it allows, and
how far the identified model is from the data themselves."""
from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ..frfit import fit_frf_auto
from ..lti import as_ss, freqresp, ss
from ._plant import MBIPlant, controlled_engineering


def true_from_frf(frf, engineering, *, excitation: str, measurement: str, tol: float = 0.02,
                  max_order: int = 24, max_residual: float = 0.2):
    r"""A state-space stand-in for a measured FRF, to serve as the true system.

    The measured response (:class:`mutext.rig.FRF`, SI units, the excitation
    and measurement of the engineering model) is fitted by a stable rational
    model (:func:`mutext.frfit.fit_frf_auto`); its inputs and outputs are
    named ``excitation`` and ``measurement``.

    Parameters
    ----------
    frf : mutext.rig.FRF
        The measured response (SI units).
    engineering : control.StateSpace or as accepted by :func:`mutext.lti.as_ss`
        The engineering model; its modes must lie in the measured band.
    excitation, measurement : str
        Names given to the stand-in's input and output (those of the engineering model).
    tol : float, optional
        Residual at which :func:`mutext.frfit.fit_frf_auto` stops raising the order.
    max_order : int, optional
        Highest order of the rational fit.
    max_residual : float, optional
        Largest RMS relative residual of the fit that is accepted.

    Raises
    ------
    ModelError
        No frequency overlap: none of the engineering model's modes lies in the
        measured band (the identification would compare the two where neither
        says anything about the other), unusable data, or data that no stable
        rational model up to ``max_order`` fits to an RMS relative residual of
        ``max_residual`` (noise, or not a frequency response): identifying
        against such a stand-in would only fit the fit's errors.

    Returns
    -------
    (control.StateSpace, mutext.frfit.RationalFit)
    """
    E = as_ss(engineering, "engineering model")
    f = np.asarray(frf.freq_hz, float)
    if f.size < 4:
        raise ModelError(f"measured FRF{_source(frf)}: need at least 4 frequencies, got {f.size}")
    modes = np.abs(np.linalg.eigvals(np.asarray(E.A, float))) / (2 * np.pi) if E.nstates else np.zeros(0)
    modes = np.unique(np.round(modes[modes > 0], 9))
    if modes.size and not np.any((modes >= f.min()) & (modes <= f.max())):
        raise ModelError(f"measured FRF{_source(frf)}: no frequency overlap: it covers {f.min():.4g}-{f.max():.4g} Hz, "
                         f"the engineering model's modes lie at {', '.join(f'{m:.4g}' for m in modes[:6])} Hz")
    if not (isinstance(max_residual, (int, float, np.integer, np.floating)) and max_residual > 0):
        raise ModelError(f"max_residual must be a positive number, got {max_residual!r}")
    fit = fit_frf_auto(2 * np.pi * f, frf.response, tol=tol, max_order=max_order)
    over = [n for n in fit.notes if n.startswith("over-fitted")]
    if not fit.residual <= max_residual or over:
        why = over[0] if over else (f"the best stable rational fit (order {fit.order}) leaves an RMS relative "
                                    f"residual of {fit.residual:.3g} > max_residual={max_residual:g}")
        raise ModelError(f"measured FRF{_source(frf)}: cannot serve as the true system: {why}; the data look "
                         "like noise or not like the response of a linear system (check the channel, the "
                         "units and the coherence), or raise max_order / max_residual knowingly")
    sys = ss(fit.system.A, fit.system.B, fit.system.C, fit.system.D, inputs=[excitation], outputs=[measurement])
    return sys, fit


def _source(frf) -> str:
    src = getattr(frf, "source", None)
    return f" {src}" if src else ""


def _true_from_measured(measured, engineering, omega, excitation, measurement, max_fit_residual, say):
    """The true system fitted to a measured FRF, and the grid cut to the measured band (default: its points)."""
    true, measured_fit = true_from_frf(measured, engineering, excitation=excitation, measurement=measurement,
                                       max_residual=max_fit_residual)
    band = 2 * np.pi * np.asarray(measured.freq_hz, float)
    if omega is None:
        omega = band
    else:
        omega = np.asarray(omega, float)
        omega = omega[(omega >= band.min()) & (omega <= band.max())]
        if omega.size == 0:
            raise ModelError(f"identify: no frequency overlap between the grid and the measured FRF "
                             f"({band.min():.4g}-{band.max():.4g} rad/s)")
    say(f"measured FRF: {measured.freq_hz.size} frequencies, "
        f"{measured.freq_hz.min():.4g}-{measured.freq_hz.max():.4g} Hz; fitted by a stable "
        f"model of order {measured_fit.order} (relative residual {measured_fit.residual:.3g})")
    return true, measured_fit, omega


def _measured_notes(plant: MBIPlant, res, measured, measured_fit) -> list:
    """How far the controlled model is from the measured data, and how the data were fitted."""
    Gm = np.asarray(measured.response, complex)
    xc = freqresp(controlled_engineering(plant, res.K), 2 * np.pi * np.asarray(measured.freq_hz, float))[0, 0]
    rel = float(np.sqrt(np.mean(np.abs(xc - Gm) ** 2 / np.abs(Gm) ** 2)))
    return [(f"against the measured data themselves the controlled model is off by {rel:.3g} "
             f"(RMS relative; the fit of the data alone leaves {measured_fit.residual:.3g})"),
            (f"true system: the measured FRF fitted by a stable model of order {measured_fit.order} "
             f"(relative residual {measured_fit.residual:.3g})"
             + (f"; {measured_fit.notes[0]}" if measured_fit.notes else ""))]
