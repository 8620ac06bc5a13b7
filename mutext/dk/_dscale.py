r"""D-scale fitting and the D-scaled plant: the rational scalings of a K step."""
from __future__ import annotations

import control as ct
import numpy as np

from ..errors import ModelError, SolverError
from ..frfit import _constant, fit_magnitude, MagnitudeFit
from ..lti import as_ss, ss
from ..mu import BlockStructure


#: the fitted D scaling of one block (:func:`mutext.frfit.fit_magnitude`)
DScaleFit = MagnitudeFit


def fit_dscale(omega, mag, order: int, weight=None, iterations: int = 8) -> DScaleFit:
    r"""Fit :math:`|\hat D(j\omega)| \approx` ``mag`` by a stable, minimum-phase, biproper :math:`\hat D`.

    The vector fit of :func:`mutext.frfit.fit_magnitude` (same parameters,
    result and errors), on :math:`|\hat D|^2` as a rational function of
    :math:`\omega^2`, made stable and minimum phase by spectral factorisation.

    Parameters
    ----------
    omega : array_like
        Positive frequencies [rad/s], shape ``(nw,)``.
    mag : array_like
        Positive magnitudes of the scaling at ``omega``, shape ``(nw,)``.
    order : int
        Order of :math:`\hat D`: 0 (a constant) to 5.
    weight : array_like, optional
        Positive weight of each frequency on the error of :math:`\log|\hat D|`,
        shape ``(nw,)`` (default 1).
    iterations : int
        Largest number of vector-fitting pole relocations.

    Returns
    -------
    DScaleFit
        As :func:`mutext.frfit.fit_magnitude` returns it.
    """
    return fit_magnitude(omega, mag, order, weight=weight, iterations=iterations)


def fit_dscale_auto(omega, mag, weight=None, max_order: int = 4, tol: float = 0.05) -> DScaleFit:
    """Lowest order (0..``max_order``) whose weighted log-magnitude error is at most ``tol``.

    If no order reaches ``tol``, the most accurate fit is returned; a higher
    order is preferred only if it lowers the error by at least 20 %.

    Parameters
    ----------
    omega : array_like
        Positive frequencies [rad/s], shape ``(nw,)``.
    mag : array_like
        Positive magnitudes of the scaling at ``omega``, shape ``(nw,)``.
    weight : array_like, optional
        Positive weight of each frequency on the error of the log magnitude,
        shape ``(nw,)`` (default 1).
    max_order : int
        Highest order tried (at most 5).
    tol : float
        Accepted error of the fit: the largest weighted error of the log
        magnitude (``DScaleFit.error``; 0.05 is about 5 % in magnitude).

    Returns
    -------
    DScaleFit
        The fit of the lowest order within ``tol``, or the most accurate one.

    Raises
    ------
    SolverError
        The fit failed at every order.
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
