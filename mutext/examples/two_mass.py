r"""The two-mass example of thesis section 2.3 (Madden, eqs. 2.12-2.24).

Two masses in a vertical chain: ``m1`` hangs from ``m2`` through the spring
``k1``; ``m2`` is held to ground by ``k2``.  A disturbance force ``f_e`` acts
on ``m1``, the control force ``u`` on ``m2``, and a sensor measures the
displacement of ``m2`` with additive noise ``eta``.

.. math::
    \begin{bmatrix} m_1 & 0 \\ 0 & m_2 \end{bmatrix}\ddot x +
    \begin{bmatrix} k_1 & -k_1 \\ -k_1 & k_1 + k_2 \end{bmatrix} x =
    \begin{bmatrix} 1 \\ 0 \end{bmatrix} f_e + \begin{bmatrix} 0 \\ 1 \end{bmatrix} u,
    \qquad y = x_2 + \eta.

The generalized plant normalises the signals by their allowed sizes
(eqs. 2.18-2.24): ``f = [f_e / f_max; eta / eta_max]``, ``z = [x1 / x_max;
u / u_max]``.  The thesis rounds ``1/0.035`` to 28.6 and ``1/50`` to 0.02;
:func:`plant` uses the exact reciprocals unless the rounded weights are given.

All quantities are SI (kg, N/m, N, m).
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import control as ct
import numpy as np

from ..errors import ModelError
from ..lti import mck_to_ss, ss

__all__ = ["TwoMass", "THESIS", "mechanical_model", "plant", "THESIS_GAMMA"]

#: The H-infinity level the thesis reports for this problem (sec. 2.3.1).
THESIS_GAMMA = 0.9671


@dataclass(frozen=True)
class TwoMass:
    """Parameters of the two-mass problem (SI units).

    Attributes
    ----------
    m1, m2 : float
        Upper mass (disturbed, performance output) and lower mass (actuated, measured) [kg].
    k1, k2 : float
        Spring m1 to m2 and spring m2 to ground [N/m].
    f_max : float
        Largest disturbance force on m1 [N].
    eta_max : float
        Largest sensor noise [m].
    x_max : float
        Allowed displacement of m1 [m].
    u_max : float
        Allowed control force [N].
    w_x, w_u : float or None
        Performance weights overriding ``1/x_max`` and ``1/u_max`` (the thesis writes 28.6 and 0.02).
    """
    m1: float = 1.0        # kg, upper mass (disturbed, performance output)
    m2: float = 2.0        # kg, lower mass (actuated, measured)
    k1: float = 450.0      # N/m, m1 to m2
    k2: float = 175.0      # N/m, m2 to ground
    f_max: float = 10.0    # N, largest disturbance force on m1
    eta_max: float = 1e-4  # m, largest sensor noise
    x_max: float = 0.035   # m, allowed displacement of m1
    u_max: float = 50.0    # N, allowed control force
    #: override the performance weights (the thesis writes 28.6 and 0.02)
    w_x: float | None = None
    w_u: float | None = None

    def with_(self, **kw) -> "TwoMass":
        """A copy with some fields changed.

        Parameters
        ----------
        **kw
            New values of fields (``m1``, ``x_max``, ...).
        """
        return replace(self, **kw)

    @property
    def weight_x(self) -> float:
        """Weight on x1 in 1/m."""
        return 1.0 / self.x_max if self.w_x is None else self.w_x

    @property
    def weight_u(self) -> float:
        """Weight on u in 1/N."""
        return 1.0 / self.u_max if self.w_u is None else self.w_u


#: The problem exactly as printed in the thesis (rounded weights 28.6 and 0.02).
THESIS = TwoMass(w_x=28.6, w_u=0.02)


def mechanical_model(p: TwoMass = THESIS) -> ct.StateSpace:
    """Physical model: inputs ``f_e`` (N on m1) and ``u`` (N on m2); outputs ``x1``, ``x2`` (m).

    Parameters
    ----------
    p : TwoMass, optional
        The parameters (default: the thesis's).
    """
    for name in ("m1", "m2", "k1", "k2"):
        if not getattr(p, name) > 0:
            raise ModelError(f"two-mass parameter {name} must be positive, got {getattr(p, name)}")
    M = np.diag([p.m1, p.m2])
    K = np.array([[p.k1, -p.k1], [-p.k1, p.k1 + p.k2]])
    return mck_to_ss(M, None, K, inputs={"f_e": 0, "u": 1}, outputs={"x1": 0, "x2": 1},
                     dof_names=["x1", "x2"])


def plant(p: TwoMass = THESIS) -> ct.StateSpace:
    """Generalized plant of eqs. 2.22-2.24.

    Inputs ``[f1, f2, u]`` (normalised disturbance, normalised noise, control
    force in N); outputs ``[z1, z2, y]`` (weighted x1, weighted u, measured x2
    in m).  Use with ``nmeas=1, ncon=1``.

    Parameters
    ----------
    p : TwoMass, optional
        The parameters (default: the thesis's).

    Examples
    --------
    >>> from mutext.examples.two_mass import plant
    >>> P = plant()
    >>> P.ninputs, P.noutputs, P.nstates
    (3, 3, 4)
    """
    for name in ("f_max", "eta_max", "x_max", "u_max"):
        if not getattr(p, name) > 0:
            raise ModelError(f"two-mass parameter {name} must be positive, got {getattr(p, name)}")
    G = mechanical_model(p)
    A, B, C = (np.asarray(X, float) for X in (G.A, G.B, G.C))
    bf, bu = B[:, [0]], B[:, [1]]
    c1, c2 = C[[0]], C[[1]]
    n = A.shape[0]
    Bw = np.hstack([bf * p.f_max, np.zeros((n, 1))])
    Cz = np.vstack([p.weight_x * c1, np.zeros((1, n))])
    Dzw = np.zeros((2, 2))
    Dzu = np.array([[0.0], [p.weight_u]])
    Dyw = np.array([[0.0, p.eta_max]])
    return ss(A, np.hstack([Bw, bu]), np.vstack([Cz, c2]),
              np.block([[Dzw, Dzu], [Dyw, np.zeros((1, 1))]]),
              inputs=["f1", "f2", "u"], outputs=["z1", "z2", "y"],
              states=["x1", "x2", "dx1", "dx2"])
