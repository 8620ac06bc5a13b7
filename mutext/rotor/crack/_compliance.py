r"""Open-crack compliance from fracture mechanics: the strip integrals of :math:`c_{55}` and :math:`c_{44}`.

:func:`crack_compliance_dimensionless` integrates the stress-intensity
factor of the edge-cracked strips of a circular section ([PD87]_, [TPI]_);
:func:`crack_compliance` scales it to a shaft, :func:`crack_rotational_stiffness`
inverts it.  See :mod:`mutext.rotor.crack` for the model and the references.
"""
from __future__ import annotations

from functools import lru_cache

import casadi as ca
import numpy as np

from ...errors import ModelError
from ._common import _depth, _positive, _scalar, _symbolic

#: The two bending compliances of the crack, in the notation of [PD87]_.
COMPONENTS = (55, 44)


def _component(component) -> int:
    """55 or 44 from 55, 44, "c55" or "c44"."""
    if isinstance(component, str) and component.lower() in ("c55", "c44", "55", "44"):
        return int(component.lower().lstrip("c"))
    if not isinstance(component, bool) and isinstance(component, (int, np.integer)) and int(component) in COMPONENTS:
        return int(component)
    raise ModelError(f"component must be 55 (moment parallel to the crack edge) or 44 (moment "
                     f"perpendicular to it), or 'c55'/'c44', got {component!r}")


def _F1(lam, ratio):
    # edge-cracked strip in tension ([TPI]_); ratio = alpha/h, lam = pi alpha/(2h)
    return ca.sqrt(ca.tan(lam) / lam) * (0.752 + 2.02 * ratio + 0.37 * (1.0 - ca.sin(lam))**3) / ca.cos(lam)


def _F2(lam):
    # edge-cracked strip in pure bending ([TPI]_)
    return ca.sqrt(ca.tan(lam) / lam) * (0.923 + 0.199 * (1.0 - ca.sin(lam))**4) / ca.cos(lam)


@lru_cache(maxsize=8)
def _cbar_function(n_quad: int, component: int = 55) -> ca.Function:
    r"""CasADi function :math:`\bar a \mapsto \bar c_{55}(\bar a)` or :math:`\bar c_{44}(\bar a)` (:math:`\bar a = a/R`)."""
    abar = ca.SX.sym("abar")
    xu, wu = np.polynomial.legendre.leggauss(n_quad)
    u = (xu + 1.0) * np.pi / 4.0          # u in (0, pi/2): xi = b sin u
    wu = wu * np.pi / 4.0
    xs, ws = np.polynomial.legendre.leggauss(n_quad)
    s = (xs + 1.0) / 2.0                  # s in (0, 1): y = alpha_xi * s
    ws = ws / 2.0
    b = ca.sqrt(abar * (2.0 - abar))      # half width of the crack, b/R
    total = 0
    for ui, wi in zip(u, wu):
        xi = b * np.sin(ui)
        dxi = b * np.cos(ui)
        r = ca.sqrt(1.0 - xi**2)          # half height of the strip, h/(2R)
        alpha = r - (1.0 - abar)          # local crack depth of the strip, /R
        h = 2.0 * r
        inner = 0
        for sj, wj in zip(s, ws):
            y = alpha * sj
            lam = np.pi * y / (2.0 * h)
            F = _F2(lam) if component == 55 else _F1(lam, y / h)
            inner += wj * y * F**2
        # stress on the strip: ~ sqrt(1 - xi^2) (c55, bending of the strip), ~ xi (c44, tension)
        weight = (1.0 - xi**2) if component == 55 else xi**2
        total += wi * dxi * alpha * weight * inner
    # symmetric in xi: twice the integral over xi in (0, b)
    cbar = 2.0 * 32.0 / np.pi * total
    # the integrand is 0/0 at zero depth: the compliance is exactly 0 there
    cbar = ca.if_else(abar > 0, cbar, 0.0, True)
    return ca.Function(f"crack_cbar{component}", [abar], [cbar])


def crack_compliance_dimensionless(depth_ratio, *, n_quad: int = 16, component=55):
    r"""Dimensionless bending compliance :math:`\bar c_{55}` or :math:`\bar c_{44}` of an open crack.

    The crack is a straight-fronted transverse surface crack of depth
    :math:`a` in a circular shaft of radius :math:`R = D/2`; :math:`\xi` is
    the coordinate along the crack edge (from the centre line of the crack)
    and :math:`\alpha` the depth coordinate.  Following [DP83]_ and [PD87]_,
    the crack is cut into strips of width :math:`d\xi` parallel to the depth
    direction; each strip (height :math:`h = 2\sqrt{R^2-\xi^2}`, local crack
    depth :math:`\alpha_\xi = \sqrt{R^2-\xi^2} - (R-a)`) is treated as an
    edge-cracked strip, and the additional strain energy
    :math:`U = \frac{1-\nu^2}{E}\int_A K_I^2\,dA` (plane strain) gives the
    compliance :math:`c = \partial^2 U/\partial M^2`.

    * ``component=55``: the bending moment :math:`M_5` whose vector is
      parallel to the crack edge (it opens the crack).  The strip is bent,
      with the outer-fibre stress of the shaft at its ends,

      .. math::
          K_I = \sigma_5\sqrt{\pi\alpha}\,F_2(\alpha/h),\qquad
          \sigma_5 = \frac{4M_5\sqrt{R^2-\xi^2}}{\pi R^4},\qquad
          F_2 = \sqrt{\frac{\tan\lambda}{\lambda}}\;
          \frac{0.923 + 0.199\,(1-\sin\lambda)^4}{\cos\lambda}.

    * ``component=44``: the bending moment :math:`M_4` whose vector is
      perpendicular to the crack edge.  The bending stress varies along the
      edge, so each strip is loaded (nearly) in tension by the stress at its
      distance :math:`\xi` from the neutral axis,

      .. math::
          K_I = \sigma_4\sqrt{\pi\alpha}\,F_1(\alpha/h),\qquad
          \sigma_4 = \frac{4M_4\,\xi}{\pi R^4},\qquad
          F_1 = \sqrt{\frac{\tan\lambda}{\lambda}}\;
          \frac{0.752 + 2.02\,(\alpha/h) + 0.37\,(1-\sin\lambda)^3}{\cos\lambda}.

    with :math:`\lambda = \pi\alpha/(2h)` ([TPI]_: single-edge-cracked strip
    in pure bending, :math:`F_2`, and in tension, :math:`F_1`).  In the
    variables :math:`\bar\xi = \xi/R`, :math:`\bar\alpha = \alpha/R`,
    :math:`\bar a = a/R` ([PD87]_, [Pap04]_):

    .. math::
        c_{55} = \frac{1-\nu^2}{E R^3}\,\bar c_{55},\qquad
        \bar c_{55}(\bar a) = \frac{32}{\pi}\int_{-\bar b}^{\bar b}
        \int_0^{\bar\alpha_\xi} (1-\bar\xi^2)\,\bar\alpha\,
        F_2^2\!\left(\frac{\bar\alpha}{2\sqrt{1-\bar\xi^2}}\right)
        d\bar\alpha\,d\bar\xi,

    .. math::
        c_{44} = \frac{1-\nu^2}{E R^3}\,\bar c_{44},\qquad
        \bar c_{44}(\bar a) = \frac{32}{\pi}\int_{-\bar b}^{\bar b}
        \int_0^{\bar\alpha_\xi} \bar\xi^2\,\bar\alpha\,
        F_1^2\!\left(\frac{\bar\alpha}{2\sqrt{1-\bar\xi^2}}\right)
        d\bar\alpha\,d\bar\xi,

    with :math:`\bar b = \sqrt{1-(1-\bar a)^2}` and
    :math:`\bar\alpha_\xi = \sqrt{1-\bar\xi^2} - (1-\bar a)`.  (Some authors
    tabulate :math:`\pi\bar c`; the normalisation here has no :math:`\pi`.)
    :math:`c_{55}` is the larger: :math:`c_{44}/c_{55}` is about 0.07 at
    :math:`a/D = 0.1`, 0.15 at 0.2, 0.26 at 0.3, 0.42 at 0.4 and 0.68 at
    0.5.  The crack's narrow width (:math:`2b \approx 2\sqrt{aD}`) puts
    little of it far from the neutral axis of :math:`M_4`, so for shallow
    cracks :math:`\bar c_{55} \propto \bar a^{5/2}` but
    :math:`\bar c_{44} \propto \bar a^{7/2}`.

    The coupling :math:`c_{45}` of the two moments vanishes: under
    :math:`M_4` the stress-intensity factor is odd in :math:`\bar\xi`, under
    :math:`M_5` even, so the cross term of :math:`K_I^2` cancels over the
    straight front.  Tables that integrate over one half of the front only
    (:math:`0 \le \bar\xi \le \bar b`, the half in tension under
    :math:`M_4`, as for a crack whose other half closes) list a non-zero
    :math:`c_{45}` and half the :math:`c_{44}` given here; the open crack
    here is linear, a notch whose faces do not touch, and counts the whole
    front (``tests/test_crack_compliance.py`` compares both).

    The double integral is evaluated by a fixed tensor Gauss-Legendre rule
    (``n_quad`` x ``n_quad`` points) after the substitutions
    :math:`\bar\xi = \bar b\sin u` and :math:`\bar\alpha = \bar\alpha_\xi s`,
    which make the integrand smooth up to :math:`a/D = 0.5`.  The rule is a
    fixed, smooth expression of the depth, so CasADi differentiates it
    exactly (IPOPT can tune the depth); with the default 16 points it agrees
    with adaptive quadrature to better than 1e-9 relative for
    :math:`\bar c_{55}` and 2e-8 for :math:`\bar c_{44}` over
    :math:`0 < a/D \le 0.5`.

    Parameters
    ----------
    depth_ratio : float, array_like or casadi.SX/MX scalar
        Crack depth over shaft diameter, :math:`a/D \in [0, 0.5]`.  Note the
        integrals above are written in :math:`\bar a = a/R = 2a/D`.
    n_quad : int
        Gauss points per direction.
    component : {55, 44, "c55", "c44"}
        Which compliance: 55 (moment parallel to the crack edge, default)
        or 44 (moment perpendicular to it).

    Returns
    -------
    float, numpy.ndarray or casadi expression
        :math:`\bar c_{55}` or :math:`\bar c_{44}` (dimensionless); 0 at
        zero depth.  Reference values of :math:`\bar c_{55}`: 0.0277722 at
        :math:`a/D = 0.05`, 0.724880 at 0.2, 3.97355 at 0.4; of
        :math:`\bar c_{44}`: 0.109043 at 0.2, 1.65513 at 0.4 (see the tests).

    Notes
    -----
    Both vanish faster than the depth, so their derivative with respect to
    depth vanishes at zero depth; the expression is evaluated as exactly 0
    there (its derivative there is returned as 0).
    """
    if isinstance(n_quad, bool) or not isinstance(n_quad, (int, np.integer)) or not 1 <= n_quad <= 200:
        raise ModelError(f"n_quad must be an integer number of Gauss points in 1..200, got {n_quad!r}")
    f = _cbar_function(int(n_quad), _component(component))
    if isinstance(depth_ratio, ca.DM):
        depth_ratio = np.array(depth_ratio, dtype=float).squeeze()
    if isinstance(depth_ratio, (ca.SX, ca.MX)):
        return f(2.0 * _depth(depth_ratio))
    arr = np.asarray(depth_ratio, dtype=float)
    if arr.ndim == 0:
        return float(f(2.0 * _depth(arr)))
    return np.array([float(f(2.0 * _depth(v))) for v in arr.ravel()]).reshape(arr.shape)


def crack_compliance(depth_ratio, E, D, nu=0.3, *, n_quad: int = 16, component=55):
    r"""Additional rotational compliance of an open crack, in rad/(N m).

    .. math::
        c_{55}(a/D) = \frac{(1-\nu^2)\,\bar c_{55}(2a/D)}{E\,(D/2)^3},\qquad
        c_{44}(a/D) = \frac{(1-\nu^2)\,\bar c_{44}(2a/D)}{E\,(D/2)^3}

    with :math:`\bar c_{55}, \bar c_{44}` from
    :func:`crack_compliance_dimensionless` ([DP83]_, [PD87]_).  A bending
    moment :math:`M` (N m) produces an extra relative rotation
    :math:`\Delta\theta = c\,M` (rad) of the two faces, in the plane of the
    moment: :math:`c_{55}` for the moment parallel to the crack edge (the one
    that opens the crack, bending in the plane of the crack normal),
    :math:`c_{44}` for the moment perpendicular to it.  For orientation:
    :math:`c_{55}\,EI` is the shaft length with the same flexibility, about
    :math:`1.42\,D` for the rig crack (:math:`a/D = 0.4`, :math:`\nu = 0.3`);
    :math:`c_{44}\,EI` is about :math:`0.59\,D`.

    Parameters
    ----------
    depth_ratio : float or casadi scalar
        :math:`a/D \in [0, 0.5]`.
    E : float or casadi scalar
        Young's modulus [Pa].
    D : float or casadi scalar
        Shaft diameter at the crack [m].
    nu : float or casadi scalar
        Poisson's ratio [-] (plane-strain factor :math:`1-\nu^2`).
    component : {55, 44, "c55", "c44"}
        Which compliance (default 55, the moment parallel to the crack edge).
    n_quad : int, optional
        Gauss-Legendre points of the strip integration along the crack edge.

    Returns
    -------
    float or casadi expression
        Compliance [rad/(N m)]; 0 at zero depth.
    """
    E = _positive(E, "E (Young's modulus)", "Pa")
    D = _positive(D, "D (shaft diameter)", "m")
    nu = _scalar(nu, "nu (Poisson's ratio)")
    if not _symbolic(nu) and not -1.0 < nu < 0.5:
        raise ModelError(f"nu (Poisson's ratio) must lie in (-1, 0.5), got {nu}")
    R = D / 2.0
    cbar = crack_compliance_dimensionless(depth_ratio, n_quad=n_quad, component=component)
    return (1.0 - nu**2) * cbar / (E * R**3)


def crack_rotational_stiffness(depth_ratio, E, D, nu=0.3, *, n_quad: int = 16):
    r"""Rotational spring stiffness :math:`k_c = 1/c(a/D)` of an open crack, in N m/rad.

    Infinite at zero depth (no crack).  For an optimisation over the depth
    prefer :func:`cracked_element_stiffness`, which uses the compliance and
    stays finite; see :func:`crack_compliance` for the parameters.

    Parameters
    ----------
    depth_ratio : float or casadi scalar
        Crack depth over shaft diameter, :math:`a/D \in [0, 0.5]`.
    E : float or casadi scalar
        Young's modulus [Pa].
    D : float or casadi scalar
        Shaft diameter at the crack [m].
    nu : float or casadi scalar, optional
        Poisson's ratio.
    n_quad : int, optional
        Gauss-Legendre points of the strip integration along the crack edge.
    """
    c = crack_compliance(depth_ratio, E, D, nu, n_quad=n_quad)
    if _symbolic(c):
        return 1.0 / c
    return np.inf if c == 0.0 else 1.0 / c
