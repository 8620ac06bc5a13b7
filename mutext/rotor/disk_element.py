r"""Rigid disks and lumped masses: :class:`DiskElement`, :class:`PointMass`.

References
----------
.. [Fri] M. I. Friswell, J. E. T. Penny, S. D. Garvey and A. W. Lees,
   *Dynamics of Rotating Machines*, Cambridge University Press, 2010, ch. 5
   (disks, bearings, Timoshenko shaft elements, example 5.9.1).
"""
from __future__ import annotations

import math

import casadi as ca

from ..errors import ModelError
from .element import Element, _positive

__all__ = ["DiskElement", "PointMass"]


class DiskElement(Element):
    r"""Rigid disk lumped at a station (Friswell [Fri]_ ch. 5).

    .. math::
        M = \mathrm{diag}(m, m, I_d, I_d),\qquad
        G = \begin{bmatrix} 0&0&0&0\\0&0&0&0\\0&0&0&I_p\\0&0&-I_p&0\end{bmatrix}

    on :math:`(u, v, \theta, \psi)`, i.e. :math:`I_d\ddot\theta + \Omega I_p\dot\psi = M_\theta`
    and :math:`I_d\ddot\psi - \Omega I_p\dot\theta = M_\psi`.  In the
    ``"plane"`` layout :math:`M = \mathrm{diag}(m, I_d)`; in the ``"lumped"``
    layout :math:`M = m`.

    Parameters
    ----------
    station : int
    m : float or Param
        Mass [kg].
    Ip, Id : float or Param
        Polar and diametral (transverse) moments of inertia [kg m^2].
    name : str, optional
        Name of the element (default: its kind and station, e.g. ``"disk3"``); parameters
        without a :class:`Param` are called ``"<name>.<field>"``.
    """
    KIND = "disk"
    FIELDS = {"m": ("kg", "mass"), "Ip": ("kg m^2", "polar moment of inertia"),
              "Id": ("kg m^2", "diametral moment of inertia")}

    def __init__(self, station: int, m, Ip=0.0, Id=0.0, *, name: str | None = None):
        super().__init__((station,), name, m=m, Ip=Ip, Id=Id)
        _positive(self, "m", "Ip", "Id", allow_zero=True)

    @classmethod
    def from_geometry(cls, station: int, width: float, do: float, di: float, rho: float, *,
                      name: str | None = None) -> "DiskElement":
        r"""Disk of uniform density: :math:`m = \rho\pi(d_o^2-d_i^2)h/4`,
        :math:`I_p = m(d_o^2+d_i^2)/8`, :math:`I_d = I_p/2 + m h^2/12` (SI).

        Parameters
        ----------
        station : int
            1-based station of the disk.
        width : float
            Axial width h [m].
        do, di : float
            Outer and inner (bore) diameters [m].
        rho : float
            Density [kg/m^3].
        name : str, optional
            Name of the element (default: its kind and station, e.g. ``"disk3"``); parameters
            without a :class:`Param` are called ``"<name>.<field>"``.
        """
        if not (width > 0 and do > 0 and 0 <= di < do and rho > 0):
            raise ModelError(f"disk at station {station}: need width > 0, 0 <= di < do and rho > 0, got "
                             f"width={width}, do={do}, di={di}, rho={rho}")
        m = rho * math.pi * (do**2 - di**2) * width / 4.0
        Ip = m * (do**2 + di**2) / 8.0
        Id = Ip / 2.0 + m * width**2 / 12.0
        return cls(station, m, Ip, Id, name=name)

    def mass_matrix(self, p, layout):
        m = self.sym(p, "m")
        if layout.kind == "lumped":
            return ca.reshape(m, 1, 1)
        Id = self.sym(p, "Id")
        if layout.kind == "plane":
            return ca.diag(ca.vertcat(m, Id))
        return ca.diag(ca.vertcat(m, m, Id, Id))

    def gyroscopic_matrix(self, p, layout):
        if layout.kind != "rotor":
            return None
        Ip = self.sym(p, "Ip")
        G = ca.SX(4, 4)
        G[2, 3] = Ip
        G[3, 2] = -Ip
        return G


class PointMass(DiskElement):
    """A lumped mass [kg] without rotary inertia (for lumped chains; in a rotor: mass in x and y only).

    Parameters
    ----------
    node : int
        1-based station or mass number.
    m : float or Param
        Mass [kg].
    name : str, optional
        Name of the element (default: its kind and station, e.g. ``"mass3"``); parameters
        without a :class:`Param` are called ``"<name>.<field>"``.
    """
    KIND = "mass"
    FIELDS = {"m": ("kg", "mass")}

    def __init__(self, node: int, m, *, name: str | None = None):
        Element.__init__(self, (node,), name, m=m)
        _positive(self, "m", allow_zero=True)

    def mass_matrix(self, p, layout):
        m = self.sym(p, "m")
        if layout.kind == "lumped":
            return ca.reshape(m, 1, 1)
        if layout.kind == "plane":
            return ca.diag(ca.vertcat(m, 0.0))
        return ca.diag(ca.vertcat(m, m, 0.0, 0.0))

    def gyroscopic_matrix(self, p, layout):
        return None
