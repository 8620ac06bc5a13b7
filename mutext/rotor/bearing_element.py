r"""Linear bearings: springs and dampers from a station to ground (:class:`BearingElement`).

References
----------
.. [Fri] M. I. Friswell, J. E. T. Penny, S. D. Garvey and A. W. Lees,
   *Dynamics of Rotating Machines*, Cambridge University Press, 2010, ch. 5
   (disks, bearings, Timoshenko shaft elements, example 5.9.1).
"""
from __future__ import annotations

import casadi as ca

from .element import Element, _positive, _translational

__all__ = ["BearingElement"]


class BearingElement(Element):
    r"""Linear bearing at a station: springs and dampers to ground (Friswell [Fri]_ ch. 5).

    .. math::
        K = \begin{bmatrix} k_{xx} & 0\\ 0 & k_{yy}\end{bmatrix},\quad
        C = \begin{bmatrix} c_{xx} & 0\\ 0 & c_{yy}\end{bmatrix}

    on :math:`(u, v)`; in the ``"plane"`` layout :math:`k_{xx}, c_{xx}` on :math:`u`.

    Parameters
    ----------
    station : int
    k : float or Param
        Stiffness [N/m] (x, and y unless ``kyy`` is given).
    c : float or Param
        Damping [N s/m] (x, and y unless ``cyy`` is given).
    kyy, cyy : float or Param, optional
        Stiffness and damping in y for an anisotropic bearing.
    name : str, optional
        Name of the element (default: its kind and station, e.g. ``"bearing3"``); parameters
        without a :class:`Param` are called ``"<name>.<field>"``.
    """
    KIND = "bearing"
    FIELDS = {"k": ("N/m", "bearing stiffness"), "c": ("N s/m", "bearing damping"),
              "kyy": ("N/m", "bearing stiffness in y"), "cyy": ("N s/m", "bearing damping in y")}

    def __init__(self, station: int, k, c=0.0, *, kyy=None, cyy=None, name: str | None = None):
        super().__init__((station,), name, k=k, c=c, kyy=kyy, cyy=cyy)
        _positive(self, *self.FIELDS, allow_zero=True)

    def dofs(self, layout):
        return _translational(self, layout, self.nodes[0])

    def _diag(self, p, layout, xx, yy):
        a = self.sym(p, xx)
        if layout.kind != "rotor":
            return ca.reshape(a, 1, 1)
        b = self.sym(p, yy) if self.has(yy) else a
        return ca.diag(ca.vertcat(a, b))

    def stiffness_matrix(self, p, layout):
        return self._diag(p, layout, "k", "kyy")

    def damping_matrix(self, p, layout):
        return self._diag(p, layout, "c", "cyy")
