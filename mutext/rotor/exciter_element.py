r"""The magnetic exciter: force per ampere and negative stiffness (:class:`ExciterElement`).
"""
from __future__ import annotations

import casadi as ca

from .element import Element, InputPort, _positive

__all__ = ["ExciterElement"]


class ExciterElement(Element):
    r"""Magnetic exciter (actuator) at a station, driven by a current.

    Linearized actuator force :math:`f = k_i\,i + k_x\,x` along ``direction``:
    the current input enters through the *force per ampere* :math:`k_i` [N/A]
    and the *negative stiffness* :math:`k_x \ge 0` [N/m] of a biased magnetic
    actuator is added as :math:`-k_x` to the stiffness matrix.  The element
    provides the input port ``port`` (current [A]).

    Parameters
    ----------
    station : int
    ki : float or Param
        Force per ampere [N/A].
    kx : float or Param
        Negative (open-loop) stiffness magnitude [N/m]; 0 if unknown.
    direction : str
        ``"u"``/``"x"`` (default) or ``"v"``/``"y"``.
    port : str, optional
        Input name (default ``"i<station>"``).
    name : str, optional
        Name of the element (default: its kind and station, e.g. ``"exciter3"``); parameters
        without a :class:`Param` are called ``"<name>.<field>"``.
    """
    KIND = "exciter"
    FIELDS = {"ki": ("N/A", "force per ampere"), "kx": ("N/m", "negative stiffness")}

    def __init__(self, station: int, ki, kx=0.0, *, direction: str = "u", port: str | None = None,
                 name: str | None = None):
        super().__init__((station,), name, ki=ki, kx=kx)
        _positive(self, "ki", "kx", allow_zero=True)
        self.direction = direction
        self.port = port or f"i{station}"

    def dofs(self, layout):
        return [layout.dof(self.nodes[0], self.direction)]

    def stiffness_matrix(self, p, layout):
        return ca.reshape(-self.sym(p, "kx"), 1, 1)

    def input_ports(self):
        return [InputPort(self.port, self.nodes[0], self.direction, gain=self.param_name("ki"), unit="A")]
