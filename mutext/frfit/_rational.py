r"""Rational models of one measured channel: :func:`fit_frf` at a given order (with the
held-out check of an over-fitted model), :func:`fit_frf_auto` choosing the order, and
:class:`RationalFit`."""
from __future__ import annotations

from dataclasses import dataclass, field

import control as ct
import numpy as np

from ..errors import ModelError
from ..lti import ss
from ._vf import _check_data, _check_int, _eval, _realisation, _vf

#: a held-out check is made when there are fewer than this many frequencies per state
_HELD_OUT_RATIO = 4
#: the fit is flagged when the held-out residual exceeds both this and 3 x the in-sample one
_HELD_OUT_TOL = 0.01


@dataclass
class RationalFit:
    """A stable rational model of one measured channel.

    Attributes
    ----------
    system : control.StateSpace
        Real, stable, strictly proper; one input, one output.
    order : int
        Number of states (poles).
    residual : float
        RMS relative error against the data (see the module docstring).
    omega : numpy.ndarray
        Frequencies of the data [rad/s].
    poles : numpy.ndarray
        The real poles and the upper member of each complex pair.
    notes : list of str
    held_out_residual : float or None
        With few frequencies per state: RMS relative error at every fourth
        frequency of a refit without those points (see :func:`fit_frf`).
    coefficients : numpy.ndarray
        Real coefficients of the pole-residue basis (one per real pole, two per
        pair: the real and imaginary parts of its residue).
    """
    system: ct.StateSpace
    order: int
    residual: float
    omega: np.ndarray = field(repr=False)
    poles: np.ndarray = field(repr=False)
    notes: list = field(default_factory=list)
    coefficients: np.ndarray = field(default=None, repr=False)
    held_out_residual: float | None = None

    def response(self, omega) -> np.ndarray:
        """:math:`H(j\\omega)` of the fitted model.

        Parameters
        ----------
        omega : float or array_like
            Frequencies in rad/s.
        """
        return _eval(self.poles, self.coefficients, np.asarray(omega, float))


def fit_frf(omega, response, order: int, *, iterations: int = 30, tol: float = 1e-8) -> RationalFit:
    r"""Fit a stable, strictly proper rational model of ``order`` states to FRF data.

    Parameters
    ----------
    omega : array_like
        Frequencies [rad/s], positive.
    response : array_like
        Complex response at ``omega`` (e.g. m/N).
    order : int
        Number of poles (an even number gives conjugate pairs only).  At most
        the number of frequencies: each state brings two real unknowns (pole
        and residue), each frequency two real data.
    iterations : int
        Largest number of pole relocations.
    tol : float
        Stop when the poles move by less than this (relative).

    Returns
    -------
    RationalFit
        With fewer than 4 frequencies per state the fit is repeated without
        every fourth frequency and its residual on those held-out points is
        stored in ``held_out_residual``; a fit that only reproduces the points
        it was fitted to (held-out residual above 1 % and 3 x the in-sample
        residual) gets a note saying it is over-fitted.

    Raises
    ------
    ModelError
        Malformed data, an order that is not a positive integer or larger
        than the number of frequencies (the data cannot determine the model).

    Examples
    --------
    >>> import numpy as np
    >>> from mutext.frfit import fit_frf
    >>> w = np.linspace(0.1, 30.0, 300)                 # rad/s
    >>> fit = fit_frf(w, 1.0 / (100.0 - w ** 2 + 0.2j * w), 2)
    >>> np.round(np.sort_complex(fit.poles), 4), bool(fit.residual < 1e-10)
    (array([-0.1+9.9995j]), True)
    """
    w, G = _check_data(omega, response)
    if not (isinstance(order, (int, np.integer)) and not isinstance(order, (bool, np.bool_)) and order >= 1):
        raise ModelError(f"FRF fit: order must be a positive integer, got {order!r}")
    _check_int(iterations, "iterations", 0)
    if not (isinstance(tol, (int, float, np.integer, np.floating)) and np.isfinite(tol) and tol > 0):
        raise ModelError(f"FRF fit: tol must be a positive finite number, got {tol!r}")
    if order > w.size:
        raise ModelError(f"FRF fit: order {order} is larger than the number of frequencies ({w.size}): "
                         f"{2 * order} real unknowns from {2 * w.size} real data, the model is not "
                         f"determined by the data (use order <= {w.size}, or much less to average noise)")
    poles, x, res = _vf(w, G, int(order), iterations, tol)
    notes = []
    held = None
    if _HELD_OUT_RATIO * order > w.size:
        test = np.zeros(w.size, bool)
        test[2:-1:4] = True          # every fourth point, never the end points
        train = ~test
        if test.any() and order <= train.sum():
            pt, xt, _ = _vf(w[train], G[train], int(order), iterations, tol)
            Ht = _eval(pt, xt, w[test])
            held = float(np.sqrt(np.mean(np.abs(Ht - G[test]) ** 2 / np.abs(G[test]) ** 2)))
        else:
            held = float("inf")
        if not held <= max(_HELD_OUT_TOL, 3.0 * res):
            notes.append(f"over-fitted: order {order} on {w.size} frequencies reproduces the data "
                         f"(residual {res:.3g}) but refitted without every fourth frequency it misses those "
                         f"by {held:.3g} (RMS relative); the model is not reliable between the data points "
                         f"-- lower the order or measure more frequencies")
    A, B, C = _realisation(poles, x)
    sys = ss(A, B, C, np.zeros((1, 1)))
    fit = RationalFit(sys, A.shape[0], res, w, poles, notes, x)
    fit.held_out_residual = held
    return fit


def fit_frf_auto(omega, response, *, max_order: int = 24, tol: float = 0.02, min_order: int = 2) -> RationalFit:
    """The lowest even order (from ``min_order``) whose :func:`fit_frf` residual is at most ``tol``.

    If none reaches it up to ``max_order``, the best fit is returned with a note
    (noisy data: ``tol`` below the noise level cannot be reached).  Orders
    above the number of frequencies are not tried (with a note).

    Parameters
    ----------
    omega : (N,) array_like
        Frequencies in rad/s.
    response : (N,) complex array_like
        The measured response at ``omega``.
    max_order : int, optional
        Highest order tried.
    tol : float, optional
        Target RMS relative residual.
    min_order : int, optional
        Lowest order tried (rounded up to an even number, at least 2).

    Raises
    ------
    ModelError
        Malformed data; ``max_order`` or ``min_order`` not an integer, or no
        even order >= 2 between them; ``tol`` not a positive finite number.
    """
    _check_int(max_order, "max_order", 1)
    _check_int(min_order, "min_order", 0)
    if not (isinstance(tol, (int, float, np.integer, np.floating)) and np.isfinite(tol) and tol > 0):
        raise ModelError(f"FRF fit: tol must be a positive finite number, got {tol!r}")
    first = max(2, min_order + min_order % 2)
    if max_order < first:
        raise ModelError(f"FRF fit: max_order={max_order} leaves no even order to try "
                         f"(orders start at {first}; min_order={min_order})")
    w, G = _check_data(omega, response)
    top = min(max_order, w.size)
    if top < first:
        raise ModelError(f"FRF fit: {w.size} frequencies cannot determine a model of order {first} or more")
    best = None
    for n in range(first, top + 1, 2):
        f = fit_frf(w, G, n)
        if best is None or (f.residual < best.residual * 0.98 and not f.notes):
            best = f
        if f.residual <= tol and not any(m.startswith("over-fitted") for m in f.notes):
            return f
    best.notes.append(f"no order up to {top} reached the residual {tol:.3g}; "
                      f"best {best.residual:.3g} at order {best.order}"
                      + (f" (max_order {max_order} capped at the {w.size} frequencies)" if top < max_order else ""))
    return best
