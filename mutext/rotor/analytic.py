r"""Closed-form natural frequencies of uniform beams: the references the finite elements are checked against.

Euler-Bernoulli beam ([Fri]_ ch. 5):

.. math::
    \omega_n = (\beta_n L)^2 \sqrt{\frac{EI}{\rho A L^4}},

with :math:`\beta_n L = n\pi` pinned-pinned, the roots of
:math:`\cos x\cosh x = -1` clamped-free (cantilever) and of
:math:`\cos x\cosh x = 1` free-free (elastic modes; the two rigid-body modes
are not counted).  Pinned-pinned Timoshenko beam: with the mode shape
:math:`\sin kx`, :math:`k = n\pi/L`,

.. math::
    \det\begin{bmatrix} \kappa GA k^2 - \rho A\omega^2 & -\kappa GA k\\
    -\kappa GA k & EIk^2 + \kappa GA - \rho I\omega^2\end{bmatrix} = 0 ,

a quadratic in :math:`\omega^2` whose smaller root is the bending mode.
SI units; frequencies in rad/s.

.. [Fri] M. I. Friswell, J. E. T. Penny, S. D. Garvey, A. W. Lees, *Dynamics of
   Rotating Machines*, Cambridge University Press, 2010.
"""
from __future__ import annotations

import math

from ..errors import ModelError

__all__ = ["SUPPORTS", "beta_l", "euler_bernoulli_frequency", "timoshenko_pinned_frequency"]

#: Supports with a closed-form Euler-Bernoulli solution.
SUPPORTS = ("pinned", "cantilever", "free")


def beta_l(support: str, mode: int) -> float:
    r""":math:`\beta_n L` of Euler-Bernoulli mode ``mode`` (1-based) of a beam with ``support``.

    Parameters
    ----------
    support : str
        One of :data:`SUPPORTS` (``"pinned"``, ``"cantilever"``, ``"free"``, ...).
    mode : int
        1-based mode number.

    Examples
    --------
    >>> from mutext.rotor.analytic import beta_l
    >>> round(beta_l("cantilever", 1), 6), round(beta_l("free", 1), 6)
    (1.875104, 4.730041)
    """
    n = _mode(mode)
    if support == "pinned":
        return n * math.pi
    if support not in SUPPORTS:
        raise ModelError(f"beam support must be one of {SUPPORTS}, got {support!r}")
    # cos x cosh x = -+1 divided by cosh x (no overflow); root n lies within 0.4 of (2n -+ 1) pi / 2
    sign, centre = (1.0, (2 * n - 1) * math.pi / 2) if support == "cantilever" else (-1.0, (2 * n + 1) * math.pi / 2)
    return _bisect(lambda x: math.cos(x) + sign / math.cosh(x), centre - 0.4, centre + 0.4)


def euler_bernoulli_frequency(mode: int, length: float, E: float, rho: float, A: float, I: float,
                              support: str = "pinned") -> float:
    r"""Natural frequency [rad/s] of Euler-Bernoulli mode ``mode`` of a uniform beam.

    Parameters
    ----------
    mode : int
        1-based (elastic) mode number.
    length, E, rho, A, I : float
        Length [m], Young's modulus [Pa], density [kg/m^3], section area [m^2]
        and second moment of area [m^4].
    support : {"pinned", "cantilever", "free"}
        Pinned-pinned, clamped-free or free-free.

    Examples
    --------
    >>> from mutext.rotor.analytic import euler_bernoulli_frequency
    >>> round(euler_bernoulli_frequency(1, 1.0, E=1.0, rho=1.0, A=1.0, I=1.0), 6)   # pi^2
    9.869604
    """
    return beta_l(support, mode) ** 2 * math.sqrt(E * I / (rho * A * length**4))


def timoshenko_pinned_frequency(mode: int, length: float, E: float, G: float, rho: float, A: float, I: float,
                                kappa: float) -> float:
    r"""Bending natural frequency [rad/s] of mode ``mode`` of a pinned-pinned Timoshenko beam.

    ``G`` is the shear modulus [Pa] and ``kappa`` the shear coefficient
    (:func:`mutext.rotor.elements.cowper_shear_coefficient`); the other
    arguments as in :func:`euler_bernoulli_frequency`.

    Parameters
    ----------
    mode : int
        1-based mode number.
    length : float
        Beam length [m].
    E : float
        Young's modulus [Pa].
    G : float
        Shear modulus [Pa].
    rho : float
        Density [kg/m^3].
    A : float
        Cross-section area [m^2].
    I : float
        Second moment of area [m^4].
    kappa : float
        Shear coefficient.

    Examples
    --------
    >>> from mutext.rotor.analytic import euler_bernoulli_frequency, timoshenko_pinned_frequency
    >>> A, I = 3.14e-4, 7.85e-9                      # a solid 20 mm section
    >>> t = timoshenko_pinned_frequency(1, 1.0, 2.1e11, 8.1e10, 7800.0, A, I, kappa=0.89)
    >>> round(t / euler_bernoulli_frequency(1, 1.0, 2.1e11, 7800.0, A, I), 4)   # slender: shear hardly matters
    0.9995
    """
    k = _mode(mode) * math.pi / length
    kGA = kappa * G * A
    a = rho * A * rho * I
    b = -(rho * A * (E * I * k**2 + kGA) + rho * I * kGA * k**2)
    c = kGA * E * I * k**4
    # the smaller root as 2c / (-b + sqrt(...)): (-b - sqrt(...)) / 2a cancels on a slender beam
    return math.sqrt(2 * c / (-b + math.sqrt(b * b - 4 * a * c)))


def _mode(mode) -> int:
    if isinstance(mode, bool) or int(mode) != mode or mode < 1:
        raise ModelError(f"mode must be a positive integer (1-based), got {mode!r}")
    return int(mode)


def _bisect(f, a, b):
    """The root of ``f`` in ``[a, b]`` (a sign change) to the last bit."""
    fa = f(a)
    while True:
        m = 0.5 * (a + b)
        if m in (a, b):
            return m
        fm = f(m)
        if (fm > 0) == (fa > 0):
            a, fa = m, fm
        else:
            b = m
