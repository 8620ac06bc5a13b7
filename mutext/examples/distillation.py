r"""Skogestad and Postlethwaite's distillation column with input uncertainty ([SP]_ Table 8.1,
sec. 8.12.4), the standard test of D-K iteration.

The plant is :math:`G(s) = \frac{1}{75s + 1}\begin{bmatrix}87.8 & -86.4\\ 108.2 & -109.6\end{bmatrix}`
(minutes), with a relative input uncertainty :math:`W_I(s) = (s + 0.2)/(0.5s + 1)` on each
input and the performance weight :math:`W_P(s) = 0.5\,(10s + 1)/(10s + 10^{-5})` on each
output: an integrator approximated by poles at :math:`-10^{-6}`, which remain poles of every
closed loop (see :func:`mutext.dk.near_axis_poles`).  Robust performance is
:math:`\mu < 1` for two complex ``1 x 1`` input-uncertainty blocks and a full complex
``2 x 2`` performance block.

The generalized plant has inputs ``[u_Delta (2), w (2), u (2)]`` and outputs
``[z_Delta (2), z_P (2), y (2)]``, as ``dkpy.example_skogestad2006_p325`` builds it.

References
----------
.. [SP] S. Skogestad and I. Postlethwaite, *Multivariable Feedback Control*,
   2nd ed., Wiley, 2005.

Examples
--------
>>> from mutext.examples import distillation
>>> P = distillation.plant()
>>> P.nstates, P.ninputs, P.noutputs
(6, 6, 6)
"""
from __future__ import annotations

import control as ct
import numpy as np

from ..lti import ss
from ..mu import Block, BlockStructure

__all__ = ["G0", "plant", "structure"]

#: steady-state gain of the column (LV configuration)
G0 = np.array([[87.8, -86.4], [108.2, -109.6]])


def plant() -> ct.StateSpace:
    """The generalized plant: inputs ``[u_Delta, w, u]``, outputs ``[z_Delta, z_P, y]``, two of each;
    two measurements and two controls."""
    lag = ct.tf([1], [75, 1])
    G = ct.append(lag, lag) * ct.tf(G0.reshape(2, 2, 1), np.ones((2, 2, 1)))
    Wp = 0.5 * ct.append(ct.tf([10, 1], [10, 1e-5]), ct.tf([10, 1], [10, 1e-5]))
    Wi = ct.append(ct.tf([1, 0.2], [0.5, 1]), ct.tf([1, 0.2], [0.5, 1]))
    G.name, Wp.name, Wi.name = "G", "Wp", "Wi"
    P = ct.interconnect(
        [G, Wp, Wi, ct.summing_junction(["u_w", "u_G"], dimension=2, name="sum_w"),
         ct.summing_junction(["u_del", "u_u"], dimension=2, name="sum_del"),
         ct.summing_junction(["u"], dimension=2, name="split")],
        connections=[["G.u", "sum_del.y"], ["sum_del.u_u", "split.y"], ["sum_w.u_G", "G.y"],
                     ["Wp.u", "sum_w.y"], ["Wi.u", "split.y"]],
        inplist=["sum_del.u_del", "sum_w.u_w", "split.u"], outlist=["Wi.y", "Wp.y", "-sum_w.y"])
    return ss(P.A, P.B, P.C, P.D)


def structure() -> BlockStructure:
    """Two complex scalar input-uncertainty blocks and the full ``2 x 2`` performance block."""
    return BlockStructure([Block.full(1, 1), Block.full(1, 1), Block.full(2, 2, "performance")])
