r"""Units: every quantity that enters :mod:`mutext.rotor` is converted to SI here.

Inside the package everything is SI (m, kg, s, N, Pa, rad).  Files may use the
*inch-pound* system of the thesis station tables; conversion happens once,
where the file is read, with the exact factors below.

Pound: mass or force?
---------------------
The thesis tables give "added weight" in lb, inertias in lb in\ :sup:`2` and
density in lb/in\ :sup:`3`.  We read them as **pound-mass** (lbm):
``1 lb = 0.45359237 kg`` exactly.  This is the same as reading them as
pound-force *weights* and dividing by standard gravity
:math:`g_0 = 386.0886\ \mathrm{in/s^2}`, the classical US practice
(``mass [lbf s^2/in] = weight [lbf] / g0``): both give
``4.81 lb -> 2.1818 kg``.  The other reading, in which the numbers are already
masses in the consistent unit lbf s\ :sup:`2`/in (a "slinch", 175.13 kg), is
absurd here: the 4.81 entry would be an 842 kg disk on a 0.625 in shaft, and a
density of 0.3 lbf s\ :sup:`2`/in\ :sup:`4` would be 386 times that of steel.
With the lbm reading the density 0.3 lb/in\ :sup:`3` is 8304 kg/m\ :sup:`3`
(416 stainless steel: about 7750 kg/m\ :sup:`3`; the thesis tuned the value).

Forces (stiffness, damping, force per ampere) in inch-pound files are in
pound-force: ``1 lbf = 0.45359237 kg x 9.80665 m/s^2 = 4.4482216152605 N``.
Young's modulus is in psi (lbf/in\ :sup:`2`) in model files and in Mpsi
(10\ :sup:`6` psi) in the station-table column, as the thesis writes it (30).

Table of quantities
-------------------
=====================  =====================  =============================
quantity               SI                     inch-pound
=====================  =====================  =============================
length, diameter       m                      in (0.0254 m)
mass                   kg                     lb = lbm (0.45359237 kg)
inertia                kg m^2                 lb in^2 (2.9263965e-4 kg m^2)
density (mass)         kg/m^3                 lb/in^3 (27679.905 kg/m^3)
Young's/shear modulus  Pa                     psi (6894.7573 Pa)
force                  N                      lbf (4.4482216 N)
stiffness              N/m                    lbf/in (175.12684 N/m)
damping                N s/m                  lbf s/in (175.12684 N s/m)
rotational stiffness   N m/rad                lbf in/rad (0.11298483 N m)
force per current      N/A                    lbf/A (4.4482216 N/A)
rotational compliance  rad/(N m)              rad/(lbf in)
angular speed          rad/s                  rad/s (rpm via ``speed_rpm``)
=====================  =====================  =============================
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError

__all__ = ["INCH", "POUND_MASS", "STANDARD_GRAVITY", "POUND_FORCE", "PSI", "MPSI",
           "QUANTITIES", "SYSTEMS", "to_si", "from_si", "rpm_to_rad_s", "rad_s_to_rpm"]

INCH = 0.0254                                   #: m, exact (1959 international inch)
POUND_MASS = 0.45359237                         #: kg, exact (avoirdupois pound)
STANDARD_GRAVITY = 9.80665                      #: m/s^2, exact (g0)
POUND_FORCE = POUND_MASS * STANDARD_GRAVITY     #: N = 4.4482216152605
PSI = POUND_FORCE / INCH**2                     #: Pa = 6894.757293168361
MPSI = 1.0e6 * PSI                              #: Pa, the unit of the station-table modulus column

#: SI unit of each quantity (what the package uses internally).
QUANTITIES = {
    "length": "m",
    "mass": "kg",
    "inertia": "kg m^2",
    "density": "kg/m^3",
    "modulus": "Pa",
    "force": "N",
    "moment": "N m",
    "stiffness": "N/m",
    "damping": "N s/m",
    "rotational_stiffness": "N m/rad",
    "rotational_damping": "N m s/rad",
    "rotational_compliance": "rad/(N m)",
    "force_per_current": "N/A",
    "angular_speed": "rad/s",
    "dimensionless": "1",
}

_INCH_POUND = {
    "length": (INCH, "in"),
    "mass": (POUND_MASS, "lb"),
    "inertia": (POUND_MASS * INCH**2, "lb in^2"),
    "density": (POUND_MASS / INCH**3, "lb/in^3"),
    "modulus": (PSI, "psi"),
    "force": (POUND_FORCE, "lbf"),
    "moment": (POUND_FORCE * INCH, "lbf in"),
    "stiffness": (POUND_FORCE / INCH, "lbf/in"),
    "damping": (POUND_FORCE / INCH, "lbf s/in"),
    "rotational_stiffness": (POUND_FORCE * INCH, "lbf in/rad"),
    "rotational_damping": (POUND_FORCE * INCH, "lbf in s/rad"),
    "rotational_compliance": (1.0 / (POUND_FORCE * INCH), "rad/(lbf in)"),
    "force_per_current": (POUND_FORCE, "lbf/A"),
    "angular_speed": (1.0, "rad/s"),
    "dimensionless": (1.0, "1"),
}

#: unit system name -> {quantity: (factor to SI, unit label)}
SYSTEMS = {
    "SI": {q: (1.0, u) for q, u in QUANTITIES.items()},
    "inch-pound": _INCH_POUND,
}


def _system(system: str) -> dict:
    try:
        return SYSTEMS[system]
    except KeyError:
        raise ModelError(f"unknown unit system '{system}'; expected one of {sorted(SYSTEMS)}") from None


def to_si(value: float, quantity: str, system: str = "SI") -> float:
    """Convert ``value`` of ``quantity`` from ``system`` to SI.

    Parameters
    ----------
    value : float
        The number in the units of ``system``.
    quantity : str
        A key of :data:`QUANTITIES` (``"length"``, ``"mass"``, ...).
    system : str, optional
        ``"SI"`` or ``"inch-pound"``.

    Examples
    --------
    >>> round(to_si(1.0, "length", "inch-pound"), 4)
    0.0254
    """
    sysd = _system(system)
    if quantity not in sysd:
        raise ModelError(f"unknown quantity '{quantity}'; expected one of {sorted(sysd)}")
    return float(value) * sysd[quantity][0]


def from_si(value: float, quantity: str, system: str = "SI") -> float:
    """Inverse of :func:`to_si`.

    Parameters
    ----------
    value : float
        The number in SI.
    quantity : str
        A key of :data:`QUANTITIES` (``"length"``, ``"mass"``, ...).
    system : str, optional
        ``"SI"`` or ``"inch-pound"``.
    """
    sysd = _system(system)
    if quantity not in sysd:
        raise ModelError(f"unknown quantity '{quantity}'; expected one of {sorted(sysd)}")
    return float(value) / sysd[quantity][0]


def unit_label(quantity: str, system: str = "SI") -> str:
    """Unit symbol of ``quantity`` in ``system`` (e.g. ``'lbf/in'``)."""
    return _system(system)[quantity][1]


def _scalar_or_array(x):
    a = np.asarray(x, dtype=float)
    return float(a) if a.ndim == 0 else a


def rpm_to_rad_s(rpm):
    """Revolutions per minute to rad/s (``2 pi / 60``); scalars or arrays.

    Parameters
    ----------
    rpm : float or array_like
        Speed in revolutions per minute.

    Examples
    --------
    >>> from mutext.rotor import rpm_to_rad_s, rad_s_to_rpm
    >>> round(rpm_to_rad_s(600.0), 4)
    62.8319
    >>> rad_s_to_rpm([62.83185307179586, 0.0])
    array([600.,   0.])
    """
    return _scalar_or_array(np.asarray(rpm, dtype=float) * (2.0 * math.pi / 60.0))


def rad_s_to_rpm(omega):
    """rad/s to revolutions per minute; scalars or arrays.

    Parameters
    ----------
    omega : float or array_like
        Speed in rad/s.
    """
    return _scalar_or_array(np.asarray(omega, dtype=float) * (60.0 / (2.0 * math.pi)))
