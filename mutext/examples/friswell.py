"""Friswell, Penny, Garvey & Lees, *Dynamics of Rotating Machines* (2010), example 5.9.1.

A 1.5 m steel shaft of 50 mm diameter in six Timoshenko elements, two disks
(stations 3 and 5) and isotropic 1 MN/m bearings at both ends: the reference
rotor against which the finite elements are checked (tests and benchmark).
"""
from __future__ import annotations

#: Published natural frequencies [rad/s] at 0 rpm and at 4000 rpm.
FREQUENCIES_0_RPM = [86.66, 86.66, 274.31, 274.31, 716.78, 716.78]
FREQUENCIES_4000_RPM = [85.39, 87.80, 251.78, 294.71, 600.18, 827.08]


def rotor():
    """The example's rotor, in SI units."""
    from ..rotor import BearingElement, DiskElement, Param, Rotor, ShaftElement
    E, G, rho = 211e9, 81.2e9, 7810.0
    mat = dict(E=Param("E", E, "Pa"), G=Param("G", G, "Pa"), rho=Param("rho", rho, "kg/m^3"))
    els = [ShaftElement(i, 0.25, 0.05, 0.0, **mat) for i in range(1, 7)]
    els += [DiskElement.from_geometry(3, 0.07, 0.28, 0.05, rho), DiskElement.from_geometry(5, 0.07, 0.35, 0.05, rho)]
    els += [BearingElement(1, 1e6), BearingElement(7, 1e6)]
    return Rotor(els, name="Friswell 5.9.1")
