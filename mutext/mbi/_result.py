r""":class:`MBIResult`, the result of an identification by either route (:func:`identify`'s
D-K search, :func:`identify_convex`), and the pieces both use: the reading of ``K`` on its
identifiable band and the progress log."""
from __future__ import annotations

from dataclasses import dataclass, field

import control as ct
import numpy as np

from ..lti import as_ss, freqresp
from ._floor import WzFloor
from ._impedance import ImpedanceFit, fit_impedance, identifiable_band
from ._plant import MBIPlant


@dataclass
class MBIResult:
    r"""Result of :func:`identify`.

    Attributes
    ----------
    K : control.StateSpace
        The identified dynamics (force per displacement, applied as :math:`-u`):
        :math:`K \approx D_u`.
    Wz : float
        The accepted error bound (output unit).
    mu_upper, mu_lower : float
        Certified robust-performance bounds of the final controller at ``Wz``.
    tries : list of WzTry
        Every W_z tried, in order.
    plant : MBIPlant
        The plant at the accepted ``Wz``.
    fit : ImpedanceFit
        Mass-damper-spring reading of ``K`` on its identifiable band.
    controlled : control.StateSpace
        The engineering model with ``K`` attached.
    dk : mutext.dk.DKResult or None
        The final D-K run (None from the convex route, :class:`ConvexMBIResult`).
    seconds : float
    notes : list of str
    floor : WzFloor
        The certified lower bound on any achievable ``Wz`` (:func:`wz_floor`).
    measured_fit : mutext.frfit.RationalFit or None
        When the true system was a measured FRF: the rational model that stood in
        for it, with its residual.
    omega : ndarray
        The frequency grid (rad/s) of the search.
    """
    K: ct.StateSpace
    Wz: float
    mu_upper: float
    mu_lower: float
    tries: list
    plant: MBIPlant
    fit: ImpedanceFit
    controlled: ct.StateSpace
    dk: object
    seconds: float
    omega: np.ndarray = field(repr=False, default=None)
    notes: list = field(default_factory=list)
    floor: WzFloor | None = None
    measured_fit: object = None

    def bound(self, omega=None) -> np.ndarray:
        r"""The certified error bound at ``omega`` (default: the search grid): ``Wz``, or
        :math:`W_z|S(j\omega)|` with a shaped bound (``weight="spread"``).

        Parameters
        ----------
        omega : array_like, optional
            Frequencies in rad/s (default: the search grid ``omega``).
        """
        return self.plant.bound(self.omega if omega is None else omega)

    def error(self, true_system, omega=None) -> np.ndarray:
        """|x_true - x_controlled| (output unit per input unit) of a true system over ``omega``.

        Parameters
        ----------
        true_system : control.StateSpace
            A true system with the ports ``excitation`` and ``measurement``.
        omega : array_like, optional
            Frequencies in rad/s (default: the search grid ``omega``).
        """
        omega = self.omega if omega is None else np.asarray(omega, float)
        pr = self.plant.ports
        T = as_ss(true_system)
        i = list(T.input_labels).index(pr["excitation"])
        o = list(T.output_labels).index(pr["measurement"])
        return np.abs(freqresp(T, omega)[o, i] - freqresp(self.controlled, omega)[0, 0])


def _logger(out):
    """``say(text)``: a line ``[mbi] text`` on ``out`` (nothing for ``None``)."""
    def say(text):
        if out is not None:
            print(f"[mbi] {text}", file=out, flush=True)
    return say


def _fit_on_identifiable_band(plant: MBIPlant, K, omega, notes: list) -> ImpedanceFit:
    """The impedance fit of ``K`` on its identifiable band (the whole grid if that band is too thin)."""
    sens, band = identifiable_band(plant, K, omega)
    if band.sum() < 3:
        notes.append("K has almost no identifiable band (|s K| >= 1 at fewer than 3 frequencies); "
                     "the fit uses the whole grid")
        band = np.ones_like(band)
    return fit_impedance(K, omega[band], weight=sens[band])
