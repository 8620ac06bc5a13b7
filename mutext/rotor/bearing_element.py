r"""Linear bearings: springs and dampers from a station to ground (:class:`BearingElement`).

References
----------
.. [Fri] M. I. Friswell, J. E. T. Penny, S. D. Garvey and A. W. Lees,
   *Dynamics of Rotating Machines*, Cambridge University Press, 2010, ch. 5
   (disks, bearings, Timoshenko shaft elements, example 5.9.1).
"""
from __future__ import annotations

import casadi as ca

from ..errors import ModelError
from .element import Element, _positive, _translational

__all__ = ["BearingElement"]


class BearingElement(Element):
    r"""Linear bearing at a station: springs and dampers to ground (Friswell [Fri]_ ch. 5).

    .. math::
        K = \begin{bmatrix} k_{xx} & k_{xy}\\ k_{yx} & k_{yy}\end{bmatrix},\quad
        C = \begin{bmatrix} c_{xx} & 0\\ 0 & c_{yy}\end{bmatrix}

    on :math:`(u, v)`; in the ``"plane"`` layout :math:`k_{xx}, c_{xx}` on :math:`u`.

    Sign convention: the bearing's force on the shaft is :math:`f = -K q - C\dot q` with
    :math:`q = (u, v)`, so :math:`f_x = -(k_{xx} u + k_{xy} v)` and :math:`f_y = -(k_{yx} u + k_{yy} v)`;
    ``kxy`` is the :math:`(x, y)` entry of the block (the force in x per displacement in y),
    ``kyx`` the :math:`(y, x)` entry.  A skew pair :math:`k_{xy} = -k_{yx} = q > 0` (seals,
    fluid films) pushes a forward (counter-clockwise, with the spin about +z) whirl orbit along:
    its work on a circular orbit of radius :math:`r` is :math:`+2\pi q r^2` per cycle, a destabilising
    circulatory force.

    Parameters
    ----------
    station : int
    k : float or Param
        Stiffness [N/m] (x, and y unless ``kyy`` is given).
    c : float or Param
        Damping [N s/m] (x, and y unless ``cyy`` is given).
    kyy, cyy : float or Param, optional
        Stiffness and damping in y for an anisotropic bearing.
    kxy, kyx : float or Param, optional
        Cross-coupled stiffness [N/m], either sign (default 0): force in x per displacement in y,
        force in y per displacement in x.  Two-plane rotors only (``"rotor"`` layout).
    name : str, optional
        Name of the element (default: its kind and station, e.g. ``"bearing3"``); parameters
        without a :class:`Param` are called ``"<name>.<field>"``.
    """
    KIND = "bearing"
    FIELDS = {"k": ("N/m", "bearing stiffness"), "c": ("N s/m", "bearing damping"),
              "kyy": ("N/m", "bearing stiffness in y"), "cyy": ("N s/m", "bearing damping in y"),
              "kxy": ("N/m", "cross-coupled bearing stiffness, x force per y displacement"),
              "kyx": ("N/m", "cross-coupled bearing stiffness, y force per x displacement")}
    #: The cross-coupled fields (either sign).
    CROSS = ("kxy", "kyx")

    def __init__(self, station: int, k, c=0.0, *, kyy=None, cyy=None, kxy=None, kyx=None, name: str | None = None):
        super().__init__((station,), name, k=k, c=c, kyy=kyy, cyy=cyy, kxy=kxy, kyx=kyx)
        _positive(self, *(f for f in self.FIELDS if f not in self.CROSS), allow_zero=True)

    def check(self, layout):
        super().check(layout)
        given = [f for f in self.CROSS if self.has(f)]
        if given and layout.kind != "rotor":
            raise ModelError(f"{self.name}: cross-coupled stiffness ({', '.join(given)}) needs a two-plane rotor "
                             f"(planes = 2); this model is '{layout.kind}'")

    def dofs(self, layout):
        return _translational(self, layout, self.nodes[0])

    def _diag(self, p, layout, xx, yy):
        a = self.sym(p, xx)
        if layout.kind != "rotor":
            return ca.reshape(a, 1, 1)
        b = self.sym(p, yy) if self.has(yy) else a
        return ca.diag(ca.vertcat(a, b))

    def stiffness_matrix(self, p, layout):
        K = self._diag(p, layout, "k", "kyy")
        if layout.kind == "rotor":
            if self.has("kxy"):
                K[0, 1] = self.sym(p, "kxy")
            if self.has("kyx"):
                K[1, 0] = self.sym(p, "kyx")
        return K

    def damping_matrix(self, p, layout):
        return self._diag(p, layout, "c", "cyy")
