r"""The result of the synthesis and the check every controller passes: the closed loop rebuilt
from the plant, its stability and its norm recomputed three ways.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import control as ct
import numpy as np

from ..lti import hinf_norm, lft_lower, sigma_max, stability
from ._slycot import slycot_hinf_norm


@dataclass
class HinfResult:
    r"""Result of :func:`hinfsyn`.

    Attributes
    ----------
    K : control.StateSpace
        The controller (``ncon`` outputs, ``nmeas`` inputs).
    CL : control.StateSpace
        The closed loop :math:`\mathcal F_\ell(P, K)` rebuilt from ``P`` and ``K``.
    gamma : float
        Optimal level (Riccati gamma iteration or LMIs, see ``info["level_method"]``):
        the infimum of the closed-loop norm over all stabilizing controllers (to
        the accuracy of that computation).
    gamma_target : float
        The level at which the controller was constructed (``gamma`` times
        ``1 + backoff``).
    closed_loop_norm : float
        :math:`\|\mathcal F_\ell(P, K)\|_\infty` recomputed by our Hamiltonian algorithm.
    closed_loop_norm_slycot : float
        The same norm by SLICOT AB13DD (``nan`` if unavailable).
    closed_loop_norm_grid : float
        Peak of the largest singular value on a log-spaced frequency grid (a lower bound).
    peak_frequency : float
        Frequency (rad/s) of the closed-loop peak.
    stable : bool
        All closed-loop poles in the open left half plane.
    max_closed_loop_real_part : float
        Largest real part of the closed-loop poles [rad/s] (negative for a
        stable loop).
    controller_poles : ndarray of complex
        Poles of ``K`` [rad/s], shape ``(K.nstates,)``.
    backoff : float
        The relative distance above ``gamma`` at which the returned controller
        was built (``gamma_target = gamma (1 + backoff)``).
    notes : list of str
        Properties of the problem worth knowing (singular D12/D21, D22 handling, ...).
    solver : str
        The cvxpy solver named for the LMIs.
    seconds : float
        Wall-clock time of the synthesis [s].
    info : dict
        ``level_method`` (how ``gamma`` was found), ``tries`` (every controller
        built, with its verification), ``stability`` (the verdict on the closed
        loop, naming the deciding pole), scalings.
    construction : str
        How ``K`` was built: the central controller from the Riccati solutions
        (:func:`central_controller`) or the LMI reconstruction.
    """
    K: ct.StateSpace
    CL: ct.StateSpace
    gamma: float
    gamma_target: float
    closed_loop_norm: float
    closed_loop_norm_slycot: float
    closed_loop_norm_grid: float
    peak_frequency: float
    stable: bool
    max_closed_loop_real_part: float
    controller_poles: np.ndarray
    backoff: float
    notes: list = field(default_factory=list)
    solver: str = "CLARABEL"
    seconds: float = 0.0
    info: dict = field(default_factory=dict)
    construction: str = ""

    def __post_init__(self):
        # plain floats: numpy scalars print as np.float64(...) in reports and doctests
        for name in ("gamma", "gamma_target", "closed_loop_norm", "closed_loop_norm_slycot",
                     "closed_loop_norm_grid", "peak_frequency", "max_closed_loop_real_part", "backoff"):
            setattr(self, name, float(getattr(self, name)))
        self.stable = bool(self.stable)

    @property
    def controller_order(self) -> int:
        return self.K.nstates

    @property
    def controller_rhp_poles(self) -> np.ndarray:
        return self.controller_poles[self.controller_poles.real > 0]

    def summary(self) -> str:
        """A short human-readable report."""
        lines = [
            f"optimal level             gamma = {self.gamma:.6f} ({self.info.get('level_method', 'LMI')})",
            (f"controller built at       gamma = {self.gamma_target:.6f} (backoff {self.backoff:g}; "
             f"{self.construction or 'LMI'})"),
            f"closed-loop norm (ours)         = {self.closed_loop_norm:.6f} at {self.peak_frequency:.4g} rad/s",
            f"closed-loop norm (slycot AB13DD)= {self.closed_loop_norm_slycot:.6f}",
            f"closed loop stable              = {self.stable} (max real part {self.max_closed_loop_real_part:.3g})",
            f"controller order                = {self.controller_order}, "
            f"right-half-plane poles: {len(self.controller_rhp_poles)}",
        ]
        lines += [f"note: {n}" for n in self.notes]
        return "\n".join(lines)


def _verify(P, K, nmeas, ncon):
    """Rebuild the closed loop from ``P`` and ``K``; decide stability by the
    scale-aware rule of :func:`mutext.lti.stability` (each pole against its own
    magnitude and the balanced ``A``, not the raw sign of its real part) and
    recompute the norm three ways.  Returns ``(CL, stable, max real part, norm,
    peak frequency, AB13DD norm, grid peak, Stability report)``."""
    CL = lft_lower(P, K, nmeas, ncon)
    stab = stability(CL)
    poles = stab.poles
    maxre = stab.max_real_part
    stable = stab.stable
    if stable:
        nrm = hinf_norm(CL)
        value, wpk = nrm.value, nrm.frequency
    else:
        value, wpk = np.inf, np.nan
    sly = slycot_hinf_norm(CL) if stable else np.inf
    # grid: log-spaced around the pole magnitudes, plus the peak found
    if CL.nstates:
        mags = np.abs(poles[np.abs(poles) > 0]) if poles.size else np.array([1.0])
        lo, hi = (mags.min() / 100, mags.max() * 100) if mags.size else (1e-3, 1e3)
    else:
        lo, hi = 1e-3, 1e3
    grid = np.logspace(np.log10(lo), np.log10(hi), 400)
    if np.isfinite(wpk) and wpk > 0:
        grid = np.sort(np.append(grid, wpk))
    gpk = float(sigma_max(CL, grid).max()) if stable else np.inf
    gpk = max(gpk, float(np.linalg.norm(np.asarray(CL.D, float), 2)) if CL.D.size else 0.0)
    return CL, stable, maxre, value, wpk, sly, gpk, stab
