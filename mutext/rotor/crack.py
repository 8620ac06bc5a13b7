r"""Transverse crack models for shafts: open-crack local flexibility and breathing.

Two levels of modelling are provided.

**Open crack (linear, for frequency-domain models).**  A transverse surface
crack of depth :math:`a` in a circular shaft of diameter :math:`D` adds a
concentrated rotational compliance at its location, computed from linear
elastic fracture mechanics by the strip integral of the stress-intensity
factor ([DP83]_, [PD87]_, [Pap04]_; :func:`crack_compliance`).  In the crack
frame (:math:`\xi` the crack normal, from the shaft axis to the crack mouth;
:math:`\eta` along the crack edge) the bending part of the compliance matrix
is diagonal:

.. math::
    c_{55} = \frac{1-\nu^2}{E R^3}\,\frac{32}{\pi}\int_{-\bar b}^{\bar b}
    \int_0^{\bar\alpha_\xi} (1-\bar\xi^2)\,\bar\alpha\,F_2^2\,d\bar\alpha\,d\bar\xi,
    \qquad
    c_{44} = \frac{1-\nu^2}{E R^3}\,\frac{32}{\pi}\int_{-\bar b}^{\bar b}
    \int_0^{\bar\alpha_\xi} \bar\xi^2\,\bar\alpha\,F_1^2\,d\bar\alpha\,d\bar\xi

(:math:`R = D/2`, all lengths over :math:`R`, :math:`F_1, F_2` the
tension and bending correction factors of an edge-cracked strip [TPI]_; see
:func:`crack_compliance_dimensionless`).  :math:`c_{55}` belongs to the
moment whose vector is parallel to the crack edge (bending in the
:math:`\xi z` plane, which opens the crack), :math:`c_{44}` to the moment
perpendicular to the edge (bending in the :math:`\eta z` plane).
:math:`c_{44}/c_{55}` is about 0.07 at :math:`a/D = 0.1`, 0.26 at 0.3, 0.42
at 0.4 and 0.68 at 0.5: negligible for shallow cracks only.  The mean
stiffness loss of the open crack grows with :math:`c_{55} + c_{44}` and the
difference between the two bending planes (the twice-per-revolution
asymmetry of a turning crack) with :math:`c_{55} - c_{44}`.  The
compliances enter a beam model either

* as a **cracked beam element** (:func:`cracked_element_stiffness` for one
  plane, :func:`cracked_element_stiffness_two_plane` for a rotor with two
  bending planes: :math:`K_\xi` from :math:`c_{55}` and :math:`K_\eta` from
  :math:`c_{44}` by the same element formula, rotated by the crack angle):
  the compliance is added to the flexibility matrix of the element that
  contains the crack, which is then inverted.  This needs no extra degree of
  freedom, reduces exactly to the healthy element at zero depth and is
  smooth in the depth, so it is the recommended way to add a crack to an
  assembled rotor with a symbolic (CasADi) depth ratio; or
* as a **zero-length rotational hinge** (:func:`open_crack_element`, one
  plane, :math:`c_{55}`) between two rotation DOFs of one node that share the
  translation; or
* as an **equivalent reduced second moment of area** over a short length
  (:func:`equivalent_reduced_inertia`).

In an assembled :class:`mutext.rotor.Rotor` the crack is the element
:class:`Crack` (``Crack(station, depth_ratio, orientation=..., xi=...,
perpendicular=...)``, or a ``[[crack]]`` table in a model file): it adds the
cracked-minus-intact stiffness of the host shaft element in the crack frame,
with the depth ratio as a model parameter.  By default
(``perpendicular=True``) both planes of the crack frame bend: the plane of
the crack normal through :math:`c_{55}`, the plane of the crack edge through
:math:`c_{44}`, the full bending compliance of [PD87]_.  The remaining terms
of the crack's compliance matrix do not enter: the bending-bending coupling
:math:`c_{45}` vanishes for a straight crack front, whose
stress-intensity factor under :math:`M_4` is odd along the edge and under
:math:`M_5` even (see :func:`crack_compliance_dimensionless`); the
axial-bending coupling :math:`c_{15}` needs an axial force, which the
lateral beam model neither carries nor constrains (it changes the bending
compliance only where the shaft is held axially at both ends); the shear
and torsion terms are left out (the crack's shear compliance is small
beside the bending one of a slender shaft, and torsion is not modelled).
``perpendicular=False`` (``perpendicular = false`` in a model file) is the
one-compliance (hinge) model of the older literature: it drops
:math:`c_{44}` and treats bending in the plane of the crack edge as healthy.
At the rig's depth (:math:`a/D = 0.4`, :math:`c_{44}/c_{55} = 0.42`) it
gives the thesis rotor's first mode pair (crack facing :math:`x`, at
standstill) a mean stiffness loss 1/1.44 of the full model's and a
twice-per-revolution asymmetry 1/0.56 of it.

**Breathing crack (time domain).**  A crack that opens and closes with the
shaft rotation (weight dominance) is modelled by a stiffness that varies
with the rotation angle: the Mayes-Davies cosine model and the Gasch
switching (hinge) model (:func:`open_fraction`, :func:`rotating_frame_stiffness`,
:func:`fixed_frame_stiffness`).  The time simulations that use them live
beside the others: a Jeffcott rotor with such a crack in
:func:`mutext.rotor.simulate.simulate_breathing_jeffcott`, the finite-element
rotor at speed in :mod:`mutext.rotor.periodic`.

Units are SI throughout: metres, newtons, pascals, radians, seconds.

References
----------
.. [DP83] A. D. Dimarogonas and S. A. Paipetis, *Analytical Methods in Rotor
   Dynamics*, Applied Science Publishers, London, 1983 (local flexibility of a
   cracked shaft from the strain-energy release rate).
.. [PD87] C. A. Papadopoulos and A. D. Dimarogonas, "Coupled longitudinal and
   bending vibrations of a rotating shaft with an open crack", *Journal of
   Sound and Vibration* 117(1) (1987) 81-93 (the compliance integrals for a
   circular section used here, :math:`c_{44}` and :math:`c_{55}` among
   them).
.. [Pap04] C. A. Papadopoulos, "Some comments on the calculation of the local
   flexibility of cracked shafts", *Journal of Sound and Vibration* 278
   (2004) 1205-1211 (validity of the strip integration; depth limited to
   half the diameter; tabulated dimensionless compliances against depth).
.. [TPI] H. Tada, P. C. Paris and G. R. Irwin, *The Stress Analysis of Cracks
   Handbook*, 3rd ed., ASME Press, 2000 (stress-intensity correction for a
   single-edge-cracked strip in pure bending).
.. [Ga93] R. Gasch, "A survey of the dynamic behaviour of a simple rotating
   shaft with a transverse crack", *Journal of Sound and Vibration* 160(2)
   (1993) 313-332 (switching "hinge" crack; Jeffcott rotor with a crack).
.. [MD84] I. W. Mayes and W. G. R. Davies, "Analysis of the response of a
   multi-rotor-bearing system containing a transverse crack in a rotor",
   *ASME Journal of Vibration, Acoustics, Stress and Reliability in Design*
   106 (1984) 139-145 (cosine breathing model).
.. [PF02] J. E. T. Penny and M. I. Friswell, "Simplified modelling of rotor
   cracks", *Proceedings of ISMA 2002*, Leuven, 607-615 (comparison of the
   hinge, Mayes and fracture-mechanics crack models on a Jeffcott rotor).
.. [Mad] R. J. Madden, *Identification of unmodeled dynamics in rotor systems
   using mu-synthesis approach*, M.S. thesis, Cleveland State University
   (section 1.3.2 and chapter 4: the cracked rig).
"""
from __future__ import annotations

from functools import lru_cache

import casadi as ca
import numpy as np

from ..errors import ModelError

__all__ = [
    "MAX_DEPTH_RATIO", "RIG_SHAFT_DIAMETER", "RIG_CRACK_DEPTH_RATIO", "RIG_CRACK_STATION",
    "RIG_YOUNGS_MODULUS",
    "crack_compliance_dimensionless", "crack_compliance", "crack_rotational_stiffness",
    "open_crack_element", "cracked_element_stiffness", "cracked_element_stiffness_two_plane",
    "equivalent_reduced_inertia",
    "open_fraction", "rotating_frame_stiffness", "fixed_frame_stiffness",
    "Crack",
    "BREATHING_LAWS", "BREATHING_ALIASES", "breathing_law", "breathing_weights", "breathing_fourier",
    "BreathingChoice", "face_displacement", "choose_breathing",
]

#: Largest depth ratio a/D for which the strip integration is used ([Pap04]_).
MAX_DEPTH_RATIO = 0.5

#: Cracked rig of [Mad]_ ch. 4: shaft diameter 0.625 in, in metres.
RIG_SHAFT_DIAMETER = 0.625 * 0.0254
#: Crack depth of the rig: 40 % of the diameter ([Mad]_ sec. 4.2).
RIG_CRACK_DEPTH_RATIO = 0.4
#: Station of the crack in the thesis station table (1-based, as in the thesis).
RIG_CRACK_STATION = 15
#: Young's modulus of the station tables, 30 Mpsi, in Pa.
RIG_YOUNGS_MODULUS = 30e6 * 6894.757293168361


# ----------------------------------------------------------------------------
# helpers: the same code works on floats, numpy arrays and CasADi expressions
# ----------------------------------------------------------------------------

def _symbolic(*xs) -> bool:
    return any(isinstance(x, (ca.SX, ca.MX)) for x in xs)


def _scalar(x, name: str):
    """Float for numeric input (DM and 1x1 arrays included), unchanged for SX/MX."""
    if isinstance(x, (ca.SX, ca.MX)):
        if x.numel() != 1:
            raise ModelError(f"{name} must be a scalar expression, got shape {x.shape}")
        return x
    try:
        v = float(np.asarray(x, dtype=float).reshape(()))
    except (TypeError, ValueError):
        raise ModelError(f"{name} must be a real scalar (or a CasADi scalar), got {x!r}") from None
    if not np.isfinite(v):
        raise ModelError(f"{name} must be finite, got {v}")
    return v


def _positive(x, name: str, unit: str):
    x = _scalar(x, name)
    if not _symbolic(x) and x <= 0:
        raise ModelError(f"{name} must be positive [{unit}], got {x}")
    return x


def _depth(depth_ratio):
    d = _scalar(depth_ratio, "depth_ratio")
    if not _symbolic(d) and not 0.0 <= d <= MAX_DEPTH_RATIO:
        raise ModelError(f"depth_ratio a/D must lie in [0, {MAX_DEPTH_RATIO}] (crack depth over "
                         f"shaft diameter; the fracture-mechanics strip model is not valid beyond "
                         f"half the diameter), got {d}")
    return d


def _matrix(rows):
    """Matrix from nested lists of floats or CasADi scalars."""
    flat = [e for r in rows for e in r]
    if _symbolic(*flat):
        return ca.vertcat(*[ca.horzcat(*r) for r in rows])
    return np.array(rows, dtype=float)


# ----------------------------------------------------------------------------
# open crack: local flexibility from fracture mechanics
# ----------------------------------------------------------------------------

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


def open_crack_element(depth_ratio, E, D, nu=0.3, *, n_quad: int = 16):
    r"""Stiffness of a zero-length rotational hinge (one bending plane).

    DOF order ``[w1, theta1, w2, theta2]`` (deflection in m, rotation in rad)
    of the two sides of the crack; the matrix is

    .. math::
        K_c = k_c \begin{bmatrix} 0&0&0&0\\ 0&1&0&-1\\ 0&0&0&0\\ 0&-1&0&1
        \end{bmatrix},\qquad k_c = 1/c(a/D).

    **How to use it.**  A zero-length hinge transmits the shear force, so the
    two sides share one deflection: the crack node gets one translation and
    two rotations (``w1`` and ``w2`` are the *same* global DOF).  Assemble
    the beam element on the left with ``theta1`` and the one on the right
    with ``theta2`` and add :math:`K_c`; the translation rows of :math:`K_c`
    are zero.  The matrix is invariant under the sign change of both
    rotations, so it is the same for the other plane convention
    :math:`\theta = -dw/dz`.  Not usable at zero depth (infinite stiffness):
    for a depth that may reach zero, or for a two-plane rotor, use
    :func:`cracked_element_stiffness` instead.

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

    Returns
    -------
    (4, 4) numpy.ndarray or casadi matrix [N m/rad on the rotation DOFs]
    """
    k = crack_rotational_stiffness(depth_ratio, E, D, nu, n_quad=n_quad)
    if not _symbolic(k) and not np.isfinite(k):
        raise ModelError("open_crack_element: the hinge stiffness is infinite at depth_ratio = 0; "
                         "leave the hinge out (no crack) or use cracked_element_stiffness")
    z = 0.0
    return _matrix([[z, z, z, z], [z, k, z, -k], [z, z, z, z], [z, -k, z, k]])


def _element_flexibility(L, E, I, phi):
    # cantilever clamped at node 1, tip force and moment at node 2 (Timoshenko)
    EI = E * I
    return [[L**3 / 3.0 * (1.0 + phi / 4.0) / EI, L**2 / 2.0 / EI],
            [L**2 / 2.0 / EI, L / EI]]


def cracked_element_stiffness(L, E, I, compliance, *, position=1.0, phi=0.0):
    r"""Stiffness of a beam element (one plane) containing an open crack.

    DOF order ``[w1, theta1, w2, theta2]`` with :math:`\theta` the section
    rotation, positive for :math:`\theta = dw/dz` (Euler-Bernoulli).  The
    crack lies at :math:`z_c = \text{position}\cdot L` from node 1.  The
    element clamped at node 1 and loaded at node 2 by a force :math:`F` and
    moment :math:`M` has the flexibility

    .. math::
        C = \frac{1}{EI}\begin{bmatrix} \tfrac{L^3}{3}(1+\tfrac{\phi}{4}) &
        \tfrac{L^2}{2} \\ \tfrac{L^2}{2} & L \end{bmatrix}
        + c\begin{bmatrix} d^2 & d \\ d & 1 \end{bmatrix},\qquad d = L - z_c,

    because the moment at the crack is :math:`M + F d` and the crack adds
    the rotation :math:`c\,(M + F d)` and with it the tip deflection
    :math:`c\,(M+Fd)\,d`.  Equilibrium of the free element gives the
    nodal forces :math:`f = T [F, M]^T` with
    :math:`T = [[-1, 0], [-L, -1], [1, 0], [0, 1]]`, so

    .. math:: K = T\,C^{-1}\,T^T.

    This is the formulation of [PD87]_ for a crack at the element end
    (``position=1``).  With ``compliance=0`` it is the standard
    Euler-Bernoulli (``phi=0``) or Timoshenko element
    (:math:`\phi = 12EI/(\kappa G A L^2)`); the mass matrix is unchanged by
    the crack.  For the other rotation convention (:math:`\theta=-dw/dz`)
    use :math:`S K S` with :math:`S = \mathrm{diag}(1,-1,1,-1)`.

    Parameters
    ----------
    L : float or casadi scalar
        Element length [m].
    E : float or casadi scalar
        Young's modulus [Pa].
    I : float or casadi scalar
        Second moment of area of the healthy section [m^4].
    compliance : float or casadi scalar
        Crack compliance [rad/(N m)], e.g. from :func:`crack_compliance`
        (may be a CasADi expression of a symbolic depth).
    position : float
        Crack location as a fraction of the element length, in [0, 1].
    phi : float or casadi scalar
        Timoshenko shear parameter (0 for Euler-Bernoulli).

    Returns
    -------
    (4, 4) numpy.ndarray or casadi matrix [N/m, N/rad, N m/rad]
    """
    L = _positive(L, "L (element length)", "m")
    E = _positive(E, "E (Young's modulus)", "Pa")
    I = _positive(I, "I (second moment of area)", "m^4")
    c = _scalar(compliance, "compliance")
    phi = _scalar(phi, "phi")
    if not _symbolic(c) and c < 0:
        raise ModelError(f"compliance must be >= 0 [rad/(N m)], got {c}")
    pos = _scalar(position, "position")
    if not _symbolic(pos) and not 0.0 <= pos <= 1.0:
        raise ModelError(f"position must be a fraction of the element length in [0, 1], got {pos}")
    (c11, c12), (_, c22) = _element_flexibility(L, E, I, phi)
    d = L * (1.0 - pos)
    c11, c12, c22 = c11 + c * d**2, c12 + c * d, c22 + c
    det = c11 * c22 - c12**2
    k11, k12, k22 = c22 / det, -c12 / det, c11 / det
    # K = T Kt T^T with T = [[-1, 0], [-L, -1], [1, 0], [0, 1]] written out
    a = [-k11, -k12]                                   # row of T Kt for w1: -[k11, k12]
    b = [-L * k11 - k12, -L * k12 - k22]               # theta1
    e = [k11, k12]                                     # w2
    g = [k12, k22]                                     # theta2
    rows = [a, b, e, g]
    Tcols = [[-1.0, 0.0], [-L, -1.0], [1.0, 0.0], [0.0, 1.0]]
    K = [[r[0] * t[0] + r[1] * t[1] for t in Tcols] for r in rows]
    return _matrix(K)


def cracked_element_stiffness_two_plane(L, E, I, compliance, angle, *, position=1.0, phi=0.0,
                                        compliance_eta=0.0):
    r"""Stiffness of a cracked beam element with two bending planes (fixed frame).

    DOF order (blocked by plane)
    ``[wx1, sx1, wx2, sx2, wy1, sy1, wy2, sy2]``: :math:`w_x, w_y` are the
    deflections (m) along the fixed axes :math:`x, y` and
    :math:`s_x, s_y` the section rotations in the planes :math:`xz` and
    :math:`yz`, with :math:`s_x = dw_x/dz`, :math:`s_y = dw_y/dz` for a
    slender beam (rad).  The crack normal :math:`\xi` (from the shaft axis
    towards the crack mouth) makes the angle ``angle`` with :math:`x`;
    :math:`\eta` is along the crack edge.  Bending in the :math:`\xi z`
    plane (moment vector parallel to the crack edge) sees ``compliance``
    (:math:`c_{55}`), bending in the :math:`\eta z` plane (moment vector
    perpendicular to the edge) sees ``compliance_eta`` (:math:`c_{44}`,
    :func:`crack_compliance` with ``component=44``).  In the crack frame the
    element is the uncoupled pair :math:`K_\xi` =
    :func:`cracked_element_stiffness` with :math:`c_{55}` and :math:`K_\eta`
    = the same element with :math:`c_{44}`; with :math:`\cos, \sin` of
    ``angle``:

    .. math::
        K = \begin{bmatrix} \cos^2 K_\xi + \sin^2 K_\eta &
        \cos\sin\,(K_\xi-K_\eta) \\ \cos\sin\,(K_\xi-K_\eta) &
        \sin^2 K_\xi + \cos^2 K_\eta \end{bmatrix}.

    ``compliance_eta = 0`` (the default of this low-level function, which
    is given compliances, not a depth) treats the :math:`\eta z` plane as
    healthy: the one-compliance model.  That neglect is not small for deep
    cracks: :math:`c_{44}/c_{55}` is about 0.07 at a/D = 0.1, 0.26 at 0.3,
    0.42 at 0.4 and 0.68 at 0.5, and to first order the mean stiffness loss
    grows with :math:`c_{55}+c_{44}` while the twice-per-revolution
    asymmetry grows with :math:`c_{55}-c_{44}` ([PD87]_).  The assembled
    :class:`Crack` includes :math:`c_{44}` by default.

    For a breathing crack in a finite-element rotor use
    ``compliance = open_fraction(psi) * c55``,
    ``compliance_eta = open_fraction(psi) * c44`` and
    ``angle = Omega t + angle0`` (compliance form of the breathing models).
    Parameters as in :func:`cracked_element_stiffness`; ``angle`` in rad,
    ``compliance_eta`` in rad/(N m).

    Parameters
    ----------
    L : float or casadi scalar
        Element length [m].
    E : float or casadi scalar
        Young's modulus [Pa].
    I : float or casadi scalar
        Second moment of area of the healthy section [m^4].
    compliance : float or casadi scalar
        Compliance :math:`c_{55}` [rad/(N m)] for bending in the plane of the crack normal.
    angle : float or casadi scalar
        Angle [rad] of the crack normal from the x axis.
    position : float, optional
        Crack location as a fraction of the element length, in [0, 1].
    phi : float or casadi scalar, optional
        Timoshenko shear parameter (0 for Euler-Bernoulli).
    compliance_eta : float or casadi scalar, optional
        Compliance :math:`c_{44}` [rad/(N m)] for bending in the plane of the crack edge.

    Returns
    -------
    (8, 8) numpy.ndarray or casadi matrix
    """
    Kx = cracked_element_stiffness(L, E, I, compliance, position=position, phi=phi)
    Kh = cracked_element_stiffness(L, E, I, compliance_eta, position=position, phi=phi)
    ang = _scalar(angle, "angle")
    if _symbolic(ang, Kx, Kh):
        co, si = ca.cos(ang), ca.sin(ang)
        Kx = Kx if _symbolic(Kx) else ca.DM(Kx)
        Kh = Kh if _symbolic(Kh) else ca.DM(Kh)
        return ca.vertcat(ca.horzcat(co**2 * Kx + si**2 * Kh, co * si * (Kx - Kh)),
                          ca.horzcat(co * si * (Kx - Kh), si**2 * Kx + co**2 * Kh))
    co, si = np.cos(ang), np.sin(ang)
    return np.block([[co**2 * Kx + si**2 * Kh, co * si * (Kx - Kh)],
                     [co * si * (Kx - Kh), si**2 * Kx + co**2 * Kh]])


def equivalent_reduced_inertia(I, E, compliance, length):
    r"""Second moment of area of a short "crack segment" with the crack's flexibility.

    Some authors replace the crack by a segment of length :math:`\ell`
    (typically of the order of the diameter) with a reduced second moment of
    area :math:`I_c`, chosen so that under a bending moment the segment
    rotates by the healthy amount plus the crack rotation:

    .. math::
        \frac{\ell}{E I_c} = \frac{\ell}{E I} + c
        \quad\Longrightarrow\quad I_c = \frac{I}{1 + E I c/\ell}.

    The equivalence is exact for a uniform moment over the segment and
    approximate otherwise (error of order :math:`\ell` times the moment
    gradient).

    Parameters
    ----------
    I : second moment of area of the healthy shaft [m^4]
    E : Young's modulus [Pa]
    compliance : crack compliance [rad/(N m)]
    length : segment length [m]

    Returns
    -------
    float or casadi expression [m^4]
    """
    I = _positive(I, "I", "m^4")
    E = _positive(E, "E", "Pa")
    length = _positive(length, "length", "m")
    c = _scalar(compliance, "compliance")
    return I / (1.0 + E * I * c / length)


# ----------------------------------------------------------------------------
# breathing crack
# ----------------------------------------------------------------------------

_MODELS = ("mayes", "gasch", "gaping", "open", "notch", "closed")


def open_fraction(psi, model: str = "mayes"):
    r"""Fraction :math:`f(\psi)\in[0, 1]` of the crack stiffness loss that is active.

    :math:`\psi` is the angle between the crack normal :math:`\xi` (pointing
    from the shaft axis to the crack mouth) and the direction in which the
    shaft is bent (the static deflection under weight dominance).  At
    :math:`\psi = 0` the cracked side is on the tension side and the crack is
    fully open; at :math:`\psi = \pi` it is closed.

    * ``"mayes"`` (Mayes & Davies [MD84]_):
      :math:`f = \tfrac12(1+\cos\psi)`, a smooth transition.
    * ``"gasch"`` (switching hinge, Gasch [Ga93]_): :math:`f = 1` for
      :math:`\cos\psi \ge 0` (open during the half turn in which the crack
      is in tension), :math:`f = 0` otherwise.
    * ``"gaping"`` (aliases ``"open"``, ``"notch"``): :math:`f = 1` (always
      open: a notch whose faces never touch, an asymmetric shaft).
    * ``"closed"``: :math:`f = 0` (healthy).

    Works on floats, numpy arrays and CasADi expressions.

    Parameters
    ----------
    psi : float, ndarray or casadi expression
        Angle [rad] between the crack normal and the direction of the bending deflection.
    model : {"mayes", "gasch", "gaping", "closed"}, optional
        The breathing law (:func:`open_fraction`).
    """
    if model not in _MODELS:
        raise ModelError(f"crack model must be one of {_MODELS}, got {model!r}")
    sym = _symbolic(psi)
    cos = ca.cos if sym else np.cos
    if model == "mayes":
        return 0.5 * (1.0 + cos(psi))
    if model == "gasch":
        return ca.if_else(cos(psi) >= 0, 1.0, 0.0) if sym else np.where(np.cos(psi) >= 0, 1.0, 0.0)
    one = 0.0 if model == "closed" else 1.0
    return one + 0.0 * psi


def rotating_frame_stiffness(k0, dk_xi, dk_eta, psi, model: str = "mayes"):
    r"""Shaft stiffnesses :math:`(k_\xi, k_\eta)` in the rotating crack frame, in N/m.

    .. math::
        k_\xi = k_0 - f(\psi)\,\Delta k_\xi,\qquad
        k_\eta = k_0 - f(\psi)\,\Delta k_\eta,

    with :math:`f` from :func:`open_fraction`.  For ``model="mayes"`` this is
    the Mayes-Davies law :math:`k = k_0 - \tfrac{\Delta k}{2}(1+\cos\psi)`;
    for ``"gasch"`` the stiffness switches between :math:`k_0` (closed) and
    :math:`k_0 - \Delta k` (open).  :math:`\Delta k_\xi` is the loss of the
    fully open crack for bending across the crack edge; :math:`\Delta k_\eta`
    (bending in the plane of the crack edge, from the compliance
    :math:`c_{44}`) is often taken as zero ([Ga93]_), which holds for shallow
    cracks only: for the rig's crack (:math:`a/D = 0.4`) it is about 0.44
    :math:`\Delta k_\xi` (see :class:`Crack`).

    Parameters
    ----------
    k0 : float
        Stiffness of the healthy shaft [N/m].
    dk_xi : float
        Stiffness loss of the fully open crack for bending across the crack edge [N/m].
    dk_eta : float
        Stiffness loss for bending in the plane of the crack edge [N/m].

    psi : float or ndarray
        Angle [rad] between the crack normal and the bending direction.
    model : {"mayes", "gasch", "gaping", "closed"}, optional
        The breathing law (:func:`open_fraction`).
    """
    f = open_fraction(psi, model)
    return k0 - f * dk_xi, k0 - f * dk_eta


def fixed_frame_stiffness(k0, dk_xi, dk_eta, theta, psi, model: str = "mayes"):
    r"""2x2 shaft stiffness in the fixed frame :math:`(x, y)`, in N/m.

    The crack frame :math:`(\xi, \eta)` rotates with the shaft; :math:`\xi`
    makes the angle :math:`\theta` (rad) with :math:`x`, so
    :math:`[\xi, \eta]^T = R(\theta)[x, y]^T` with
    :math:`R = [[\cos\theta, \sin\theta], [-\sin\theta, \cos\theta]]` and

    .. math::
        K(\theta,\psi) = R^T \mathrm{diag}(k_\xi, k_\eta) R
        = k_0 I - f(\psi)\left[\frac{\Delta k_\xi+\Delta k_\eta}{2} I
        + \frac{\Delta k_\xi-\Delta k_\eta}{2}
        \begin{bmatrix}\cos 2\theta & \sin 2\theta\\ \sin 2\theta & -\cos 2\theta
        \end{bmatrix}\right].

    The :math:`2\theta` terms are the parametric excitation at twice the
    running speed; multiplied by the :math:`\psi`-dependence of
    :math:`f` they produce the 1X, 2X and 3X components of a breathing
    crack.  Returns a numpy (2, 2) array (or an array of shape (2, 2, n)
    for arrays of angles).

    Parameters
    ----------
    k0 : float
        Stiffness of the healthy shaft [N/m].
    dk_xi : float
        Stiffness loss of the fully open crack for bending across the crack edge [N/m].
    dk_eta : float
        Stiffness loss for bending in the plane of the crack edge [N/m].

    theta : float or ndarray
        Angle [rad] of the crack normal from x (the shaft's rotation angle).
    psi : float or ndarray
        Angle [rad] between the crack normal and the bending direction.
    model : {"mayes", "gasch", "gaping", "closed"}, optional
        The breathing law (:func:`open_fraction`).
    """
    f = open_fraction(psi, model)
    s = 0.5 * (dk_xi + dk_eta)
    d = 0.5 * (dk_xi - dk_eta)
    c2, s2 = np.cos(2 * np.asarray(theta)), np.sin(2 * np.asarray(theta))
    return np.array([[k0 - f * (s + d * c2), -f * d * s2],
                     [-f * d * s2, k0 - f * (s - d * c2)]])


#: Breathing laws a crack in a model file may declare (``breathing = ...``).  ``"gaping"``: a
#: notch whose faces never touch (a wire-EDM slot wider than the faces move), always open and
#: turning with the shaft, so its stiffness varies at twice the running speed only; ``"mayes"``
#: and ``"gasch"``: a crack that opens and closes under the shaft's weight (once per revolution).
BREATHING_LAWS = ("gaping", "mayes", "gasch")

#: Other names accepted for a law: ``"open"`` (the name used before ``"gaping"``) and ``"notch"``.
BREATHING_ALIASES = {"open": "gaping", "notch": "gaping"}


def breathing_law(name) -> str:
    """The documented name of breathing law ``name`` (an alias resolved), or a :class:`ModelError`.

    Parameters
    ----------
    name : str
        A law of :data:`BREATHING_LAWS` or an alias of :data:`BREATHING_ALIASES`.

    Examples
    --------
    >>> from mutext.rotor.crack import breathing_law
    >>> breathing_law("mayes"), breathing_law("notch")
    ('mayes', 'gaping')
    """
    if isinstance(name, str):
        name = BREATHING_ALIASES.get(name, name)
        if name in BREATHING_LAWS:
            return name
    raise ModelError(f"breathing law must be one of {', '.join(BREATHING_LAWS)} (or the aliases "
                     f"{', '.join(BREATHING_ALIASES)}), got {name!r}")


def breathing_weights(theta, law: str):
    r"""Weights :math:`(g_{xx}, g_{yy}, g_{xy})` of a turning crack at shaft angle ``theta``.

    A crack whose normal makes the angle :math:`\theta` with :math:`x` adds, in
    the fixed frame,

    .. math::
        \Delta K(\theta) = f(\psi)\left[\cos^2\theta\,A_{xx} + \sin^2\theta\,A_{yy}
        + \sin\theta\cos\theta\,A_{xy}\right],\qquad \psi = \theta + \pi/2,

    where :math:`A_{xx}, A_{yy}, A_{xy}` are the changes of the fully open
    crack facing :math:`x`, :math:`y` and the coupling (see
    :meth:`Crack.directional_deltas`), and :math:`f` is the open fraction of
    ``law`` (:func:`open_fraction`) under weight dominance (:math:`y` up: the
    crack is open when its normal points down, :math:`\theta = -\pi/2`).
    Returns the three weights :math:`f\cos^2\theta`, :math:`f\sin^2\theta`,
    :math:`f\sin\theta\cos\theta` (arrays shaped like ``theta``).

    Parameters
    ----------
    theta : float or ndarray
        Shaft angle [rad] (the angle of the crack normal from x).
    law : str
        A breathing law (:func:`breathing_law`).
    """
    law = breathing_law(law)
    th = np.asarray(theta, dtype=float)
    f = open_fraction(th + np.pi / 2.0, law)
    c, s = np.cos(th), np.sin(th)
    return f * c * c, f * s * s, f * s * c


def breathing_fourier(law: str, n_terms: int = 16, *, samples: int = 4096) -> np.ndarray:
    r"""Fourier coefficients of :func:`breathing_weights` over one revolution.

    Returns ``c`` of shape ``(2 n_terms + 1, 3)``: row ``n_terms + m`` holds
    :math:`c_m = \frac{1}{2\pi}\int_0^{2\pi} g(\theta) e^{-jm\theta}\,d\theta` for
    the three weights, so that :math:`g(\theta) = \sum_m c_m e^{jm\theta}`.
    The Mayes law and the open crack are trigonometric polynomials (orders 3
    and 2), so their coefficients are exact; the Gasch law switches at
    :math:`\theta = 0, \pi` and its coefficients decay like :math:`1/m`
    (trapezoidal rule with the jumps on samples: error :math:`O(\text{samples}^{-2})`).

    Parameters
    ----------
    law : str
        A breathing law (:func:`breathing_law`).
    n_terms : int, optional
        Highest order m kept.
    samples : int, optional
        Samples over the revolution of the quadrature.
    """
    law = breathing_law(law)
    if isinstance(n_terms, bool) or not isinstance(n_terms, (int, np.integer)) or n_terms < 0:
        raise ModelError(f"n_terms must be a non-negative integer, got {n_terms!r}")
    samples = max(int(samples), 4 * n_terms + 8)
    samples += samples % 2                      # the jumps at 0 and pi fall on samples
    th = 2.0 * np.pi * np.arange(samples) / samples
    g = np.stack(breathing_weights(th, law), axis=1)
    if law == "gasch":
        for j in (0, samples // 2):             # the mean of both sides at a jump
            g[j] = 0.5 * (np.stack(breathing_weights(th[j] - 1e-9, law)) +
                          np.stack(breathing_weights(th[j] + 1e-9, law)))
    F = np.fft.fft(g, axis=0) / samples
    m = np.arange(-n_terms, n_terms + 1)
    return F[m % samples]


# ----------------------------------------------------------------------------
# gaping notch or breathing crack: the faces' movement under the shaft's weight
# ----------------------------------------------------------------------------

#: Standard gravity [m/s^2].
STANDARD_GRAVITY = 9.80665


def face_displacement(moment, compliance, depth):
    r"""Relative displacement of the crack faces at the mouth under a bending moment [m].

    The open crack adds the rotation jump :math:`\Delta\varphi = c_{55} M`
    between its faces ([DP83]_; :func:`crack_compliance`): the hinge model
    of [Ga93]_, in which the two faces turn about the crack front.  The mouth
    lies at the depth :math:`a` from the front, so the faces there move
    apart (moment opening the crack) or together (closing it) by

    .. math::
        \delta = a\,\Delta\varphi = a\,c_{55}\,|M|.

    This is the crack-mouth opening of the edge-cracked strip in bending
    expressed through the compliance ([TPI]_: the CMOD and the compliance
    both follow from the same stress-intensity factor); it counts the
    crack's own flexibility only, not the strain of the intact material
    over the slot width (smaller by the factor :math:`w/\ell_{eq}`, with
    :math:`\ell_{eq} = E I c_{55}` the crack's equivalent length).

    Parameters
    ----------
    moment : float
        Bending moment at the crack [N m] (sign ignored).
    compliance : float
        :math:`c_{55}` [rad/(N m)].
    depth : float
        Crack depth :math:`a` [m].
    """
    M = _scalar(moment, "moment")
    c = _scalar(compliance, "compliance")
    a = _scalar(depth, "depth")
    if c < 0 or a < 0:
        raise ModelError(f"compliance and depth must be non-negative, got {c!r} and {a!r}")
    return abs(M) * c * a


class BreathingChoice:
    """Which crack law a slot of given width follows, and why (:func:`choose_breathing`).

    Parameters
    ----------
    law : str
        ``"gaping"`` or the closing law.
    slot_width : float
        Gap between the faces at rest [m].
    face_displacement : float
        Movement of the faces at the mouth under the shaft's weight [m].
    moment : float
        Static bending moment at the crack [N m].
    reason : str
        The comparison that decided, in words.

    Attributes
    ----------
    law : str
        ``"gaping"`` or the closing law.
    slot_width : float
        Gap between the faces at rest [m] (0: a fatigue crack).
    face_displacement : float
        Movement of the faces at the mouth under the shaft's weight [m].
    moment : float
        Static bending moment at the crack [N m].
    reason : str
    """

    def __init__(self, law, slot_width, face_displacement, moment, reason):
        self.law, self.slot_width, self.face_displacement = law, float(slot_width), float(face_displacement)
        self.moment, self.reason = float(moment), reason

    def __repr__(self):
        return f"BreathingChoice({self.law!r}: {self.reason})"

    def to_dict(self) -> dict:
        return {"law": self.law, "slot_width": self.slot_width, "face_displacement": self.face_displacement,
                "moment": self.moment, "reason": self.reason}


def _slot_width(slot_width, name="slot_width") -> float:
    if isinstance(slot_width, bool) or not isinstance(slot_width, (int, float, np.integer, np.floating)):
        raise ModelError(f"{name} must be a number [m] (the gap between the crack faces at rest; 0 for a "
                         f"fatigue crack), got {slot_width!r}")
    w = float(slot_width)
    if not np.isfinite(w) or w < 0:
        raise ModelError(f"{name} must be finite and >= 0 [m] (the gap between the crack faces at rest), "
                         f"got {w!r}")
    return w


def choose_breathing(rotor, station: int, depth_ratio: float, slot_width: float, *, xi: float = 0.0,
                     closing_law: str = "mayes", gravity: float = STANDARD_GRAVITY,
                     name: str = "crack") -> BreathingChoice:
    r"""Gaping notch or breathing crack, from the slot width and the static deflection.

    The shaft's own weight bends it: the static solution :math:`K q = -g M
    e_y` (:math:`y` up, gravity on every mass of ``rotor``, which should
    not hold the crack itself) gives the host element's end forces
    :math:`f = K_e q_e` in the y-z plane and from them the bending moment at
    the crack, :math:`M(\xi L) = -f_2 + f_1\,\xi L` (the moment carried
    across the section at :math:`\xi L`).  Turning with the shaft the crack
    passes the tension and the compression side once per revolution, and its
    faces move by :math:`\pm\delta` about their rest gap,
    :math:`\delta = a\,c_{55}\,|M|` (:func:`face_displacement`).  When
    :math:`\delta` is smaller than the slot width :math:`w` the faces never
    touch: the crack is a **gaping** notch (stiffness varying at 2x only).
    Otherwise (a fatigue crack, :math:`w = 0`) it closes on the compression
    side and breathes by ``closing_law`` (Mayes by default).

    Parameters
    ----------
    rotor : Rotor
        The rotor whose weight loads the crack (bearings included, the crack
        left out: its influence on the moment of a statically determinate
        two-bearing shaft is nil).
    station, xi : int, float
        Host element and position of the crack in it.
    depth_ratio : float
        :math:`a/D`.
    slot_width : float
        :math:`w` [m], the gap between the faces at rest (0: a fatigue crack).
    closing_law : {"mayes", "gasch"}
    gravity : float
        [m/s^2].
    name : str, optional
        Name of the crack in the messages.

    Returns
    -------
    BreathingChoice
    """
    w = _slot_width(slot_width, f"{name}: slot_width")
    closing_law = breathing_law(closing_law)
    if closing_law == "gaping":
        raise ModelError(f"{name}: closing_law must be 'mayes' or 'gasch' (the law of a crack whose faces "
                         f"touch), got {closing_law!r}")
    from .shaft_element import T_YZ
    v = rotor.values()
    Mm, _, K, _ = rotor.matrices(v)
    load = np.zeros(rotor.ndof)
    ydofs = [i for i, n in enumerate(rotor.dof_names) if n.startswith("v")]
    load[ydofs] = -gravity
    F = Mm @ load
    try:
        q = np.linalg.solve(K, F)
    except np.linalg.LinAlgError:
        raise ModelError(f"{name}: the rotor's static deflection under its weight has no solution (is it "
                         f"supported? the stiffness matrix is singular)") from None
    host = rotor.shaft_element(station)
    psym = rotor._ps.symbols
    Kp = np.asarray(ca.Function("Ke", [rotor.p], [host.plane_matrices(psym)[2]])(v).full())
    Lh = float(host.nominal("L"))
    qe = np.asarray(T_YZ.full() if hasattr(T_YZ, "full") else T_YZ) @ q[host.dofs(rotor.layout)]
    f = Kp @ qe
    moment = float(-f[1] + f[0] * xi * Lh)
    D = float(host.nominal("do"))
    E = float(host.nominal("E"))
    nu = float(host.nominal("nu")) if host.has("nu") else E / (2.0 * float(host.nominal("G"))) - 1.0
    c55 = float(crack_compliance(float(depth_ratio), E, D, nu))
    delta = face_displacement(moment, c55, depth_ratio * D)
    if delta < w:
        law = "gaping"
        reason = (f"the faces move {delta * 1e6:.3g} um under the shaft's weight (M = {moment:.3g} N m at "
                  f"the crack), less than the slot width {w * 1e6:.3g} um: they never touch, a gaping notch "
                  f"(stiffness varying at 2x only)")
    else:
        law = closing_law
        reason = (f"the faces move {delta * 1e6:.3g} um under the shaft's weight (M = {moment:.3g} N m at "
                  f"the crack), at least the slot width {w * 1e6:.3g} um: they close on the compression side, "
                  f"a breathing crack ({closing_law} law)")
    return BreathingChoice(law, w, delta, moment, reason)


# ----------------------------------------------------------------------------
# crack element for the assembled rotor (mutext.rotor.assembly)
# ----------------------------------------------------------------------------

def _make_crack_class():
    from .assembly import Rotor, ShaftFlexibility
    from .element import Element
    from .shaft_element import T_XZ, T_YZ

    class Crack(ShaftFlexibility):
        r"""Open transverse crack inside a shaft element of an assembled :class:`Rotor`.

        Adds :math:`\Delta K = K(c) - K(0)` to the host shaft element (the one
        that starts at ``station``), where :math:`K(c)` is the element with the
        crack compliance :math:`c` (:func:`crack_compliance` of the depth
        ratio, the host's Young's modulus, outer diameter and Poisson's ratio)
        at ``xi * L`` from ``station``; see
        :func:`mutext.rotor.assembly.shaft_stiffness_with_compliance` and
        :func:`cracked_element_stiffness`.  The depth ratio is a model
        parameter (``"<name>.depth_ratio"``, or a shared :class:`Param`), so
        the assembled :math:`K(p)` is a CasADi function of it with exact
        derivatives.  The mass matrix is unchanged.

        Orientation (two-plane rotor).  Bending in the plane of the crack
        normal :math:`\xi` (moment parallel to the crack edge) sees
        :math:`c_{55}` and changes the element by :math:`\Delta_\xi`; bending
        in the plane of the edge :math:`\eta` (moment perpendicular to the
        edge) sees :math:`c_{44}` and changes it by :math:`\Delta_\eta`
        (:func:`crack_compliance` with ``component=55`` and ``44``).  With the
        crack normal at angle :math:`\beta` from :math:`x`, the plane changes
        are :math:`\cos^2\beta\,\Delta_\xi + \sin^2\beta\,\Delta_\eta` (x-z),
        :math:`\sin^2\beta\,\Delta_\xi + \cos^2\beta\,\Delta_\eta` (y-z) and
        the coupling :math:`\cos\beta\sin\beta\,(\Delta_\xi - \Delta_\eta)`
        (see :func:`cracked_element_stiffness_two_plane`).
        ``orientation="mean"`` uses :math:`(\Delta_\xi + \Delta_\eta)/2` in
        both planes without coupling: the stiffness of an always-open crack
        averaged over a revolution, a linear stand-in for a crack that turns
        with the shaft.  In the one-plane (x-z) layout the change is
        :math:`\cos^2\beta\,\Delta_\xi + \sin^2\beta\,\Delta_\eta` (or the
        mean).  With ``perpendicular=False``, :math:`\Delta_\eta = 0` (the
        one-compliance model).

        Parameters
        ----------
        station : int
            Left station of the host shaft element; with ``xi=0`` (default)
            the crack is at ``station`` itself (the thesis crack: station 15).
        depth_ratio : float or Param
            :math:`a/D \in [0, 0.5]`.
        orientation : float or "mean"
            :math:`\beta` [rad] (default 0: crack normal along x).
        xi : float
            Crack position as a fraction of the host element, in [0, 1].
        n_quad : int
            Gauss points of the compliance integrals.
        perpendicular : bool
            Include the compliance :math:`c_{44}` for the moment perpendicular
            to the crack edge (default ``True``: both bending compliances of
            the crack, [PD87]_).  ``False`` keeps only :math:`c_{55}` and
            treats bending in the plane of the crack edge as healthy: the
            one-compliance (hinge) model of the older literature.  It
            under-estimates the mean stiffness loss and over-estimates the
            asymmetry of a deep crack (:math:`c_{44}/c_{55} \approx 0.42` at
            a/D = 0.4: for the thesis rotor's crack the mean loss of the first
            mode pair is x1.44 and its asymmetry x0.56 with ``True``).
        breathing : {None, "gaping", "mayes", "gasch"}
            A crack that turns with the shaft (see :mod:`mutext.rotor.periodic`):
            ``orientation`` is then the angle of the crack normal from :math:`x`
            at :math:`t = 0`, the rotor is linear time-periodic at speed, and
            the time-invariant model (``frf``, ``state_space``, ``modes``)
            holds the stiffness averaged over one revolution (the
            :math:`m = 0` term of :func:`breathing_fourier`: :math:`(A_{xx} +
            A_{yy})/4` for ``"mayes"`` and ``"gasch"``, :math:`/2` for
            ``"gaping"``, the always-open notch; ``"open"`` and ``"notch"``
            are accepted for it).  Needs two bending planes.  A model file's
            ``breathing = "auto"`` chooses between them from the slot width
            (:func:`choose_breathing`); the choice is kept in
            ``breathing_choice`` (else ``None``).
        name : str, optional
            Default ``"crack<station>"``.

        Notes
        -----
        The host must be a solid shaft (the compliance integral is for a
        circular section).
        """
        KIND = "crack"
        FIELDS = {"depth_ratio": ("1", "crack depth over shaft diameter a/D")}

        def __init__(self, station: int, depth_ratio, *, orientation=0.0, xi: float = 0.0,
                     n_quad: int = 16, perpendicular: bool = True, breathing: str | None = None,
                     name: str | None = None):
            Element.__init__(self, (station, station + 1), name, depth_ratio=depth_ratio)
            if breathing is not None:
                try:
                    breathing = breathing_law(breathing)
                except ModelError as exc:
                    raise ModelError(f"{self.name}: {exc}") from None
            if breathing is not None and orientation == "mean":
                raise ModelError(f"{self.name}: a breathing crack turns with the shaft; give its angle "
                                 "at t = 0 as orientation [rad], not 'mean'")
            self.breathing = breathing
            self.breathing_choice = None
            d = self.nominal("depth_ratio")
            if not 0.0 <= d <= MAX_DEPTH_RATIO:
                raise ModelError(f"{self.name}.depth_ratio must lie in [0, {MAX_DEPTH_RATIO}] "
                                 f"(crack depth over shaft diameter), got {d:g}")
            if not (isinstance(xi, (int, float)) and 0.0 <= xi <= 1.0):
                raise ModelError(f"{self.name}: xi must be a fraction of the element in [0, 1], got {xi!r}")
            if not (orientation == "mean" or (isinstance(orientation, (int, float))
                                              and np.isfinite(orientation))):
                raise ModelError(f"{self.name}: orientation must be an angle [rad] or 'mean', "
                                 f"got {orientation!r}")
            self.orientation = orientation
            self.xi = float(xi)
            if isinstance(n_quad, bool) or not isinstance(n_quad, (int, np.integer)) or not 1 <= n_quad <= 200:
                raise ModelError(f"{self.name}: n_quad must be an integer number of Gauss points in 1..200, "
                                 f"got {n_quad!r}")
            self.n_quad = int(n_quad)
            if not isinstance(perpendicular, (bool, np.bool_)):
                raise ModelError(f"{self.name}: perpendicular must be true or false (include the "
                                 f"compliance c44 for the moment perpendicular to the crack edge), "
                                 f"got {perpendicular!r}")
            self.perpendicular = bool(perpendicular)
            self.host = None

        def bind(self, structure):
            """Find the host shaft element in ``structure`` (called by the assembly).

            Parameters
            ----------
            structure : Rotor
                The rotor; the host is its shaft element starting at the crack's station (a solid one).
            """
            if not isinstance(structure, Rotor):
                raise ModelError(f"{self.name}: a crack needs a Rotor")
            self.host = structure.shaft_element(self.nodes[0])
            if self.host.nominal("di") != 0.0:
                raise ModelError(f"{self.name}: the crack compliance is for a solid shaft, but the host "
                                 f"element '{self.host.name}' has inner diameter "
                                 f"{self.host.nominal('di'):g} m")

        def compliance(self, p, component=55):
            """Crack compliance ``c55`` (default) or ``c44`` [rad/(N m)] as an expression of ``p``.

            Parameters
            ----------
            p : mapping of str to casadi.SX
                Parameter name -> symbol (the depth ratio and the host's material and diameter).
            component : {55, 44}, optional
                Which compliance.
            """
            h = self.host
            E, D = h.sym(p, "E"), h.sym(p, "do")
            nu = h.sym(p, "nu") if h.has("nu") else E / (2.0 * h.sym(p, "G")) - 1.0
            return crack_compliance(self.sym(p, "depth_ratio"), E, D, nu, n_quad=self.n_quad,
                                    component=component)

        def crack_frame_deltas(self, p):
            r"""Plane changes :math:`(\Delta_\xi, \Delta_\eta)` (4x4) of the host element for
            bending in the plane of the crack normal (:math:`c_{55}`) and of the crack edge
            (:math:`c_{44}`); :math:`\Delta_\eta` is ``None`` with ``perpendicular=False``.

            Parameters
            ----------
            p : mapping of str to casadi.SX
                Parameter name -> symbol.
            """
            d_xi = self.plane_delta(p, self.compliance(p, 55))
            d_eta = self.plane_delta(p, self.compliance(p, 44)) if self.perpendicular else None
            return d_xi, d_eta

        @staticmethod
        def _rotated(d_xi, d_eta, co, si):
            """Two-plane change of the crack whose normal has direction cosines (co, si)."""
            out = (co**2 * ca.mtimes([T_XZ.T, d_xi, T_XZ]) + si**2 * ca.mtimes([T_YZ.T, d_xi, T_YZ])
                   + co * si * (ca.mtimes([T_XZ.T, d_xi, T_YZ]) + ca.mtimes([T_YZ.T, d_xi, T_XZ])))
            if d_eta is None:
                return out
            return (out + si**2 * ca.mtimes([T_XZ.T, d_eta, T_XZ]) + co**2 * ca.mtimes([T_YZ.T, d_eta, T_YZ])
                    - co * si * (ca.mtimes([T_XZ.T, d_eta, T_YZ]) + ca.mtimes([T_YZ.T, d_eta, T_XZ])))

        def directional_deltas(self, p, layout):
            r"""Local :math:`(A_{xx}, A_{yy}, A_{xy})`: the open crack facing :math:`x`, facing
            :math:`y`, and the coupling, so that the crack at angle :math:`\beta` adds
            :math:`\cos^2\beta A_{xx} + \sin^2\beta A_{yy} + \sin\beta\cos\beta A_{xy}`:
            :math:`A_{xx} = \Delta_\xi` in x-z and :math:`\Delta_\eta` in y-z,
            :math:`A_{yy}` the other way round, :math:`A_{xy}` the coupling of
            :math:`\Delta_\xi - \Delta_\eta`.

            Parameters
            ----------
            p : mapping of str to casadi.SX
                Parameter name -> symbol.
            layout : Layout
                The DOF numbering of the rotor (two planes for a turning crack).
            """
            if layout.kind != "rotor":
                raise ModelError(f"{self.name}: a turning crack needs two bending planes (planes = 2)")
            d_xi, d_eta = self.crack_frame_deltas(p)
            Axx, Ayy = ca.mtimes([T_XZ.T, d_xi, T_XZ]), ca.mtimes([T_YZ.T, d_xi, T_YZ])
            Axy = ca.mtimes([T_XZ.T, d_xi, T_YZ]) + ca.mtimes([T_YZ.T, d_xi, T_XZ])
            if d_eta is None:
                return Axx, Ayy, Axy
            return (Axx + ca.mtimes([T_YZ.T, d_eta, T_YZ]), Ayy + ca.mtimes([T_XZ.T, d_eta, T_XZ]),
                    Axy - ca.mtimes([T_XZ.T, d_eta, T_YZ]) - ca.mtimes([T_YZ.T, d_eta, T_XZ]))

        def stiffness_matrix(self, p, layout):
            """Stiffness change of the crack (CasADi ``SX``): the open crack at its orientation, the mean of the two orientations, or for a breathing crack the time average of its law.

            Parameters
            ----------
            p : mapping of str to casadi.SX
                Parameter name -> symbol.
            layout : Layout
                The DOF numbering of the rotor (two planes for a turning crack).
            """
            if self.breathing is not None:
                c0 = breathing_fourier(self.breathing, 0)[0].real
                Axx, Ayy, Axy = self.directional_deltas(p, layout)
                return float(c0[0]) * Axx + float(c0[1]) * Ayy + float(c0[2]) * Axy
            d_xi, d_eta = self.crack_frame_deltas(p)
            if self.orientation == "mean":
                mean = 0.5 * d_xi if d_eta is None else 0.5 * (d_xi + d_eta)
                if layout.kind == "plane":
                    return mean
                return ca.mtimes([T_XZ.T, mean, T_XZ]) + ca.mtimes([T_YZ.T, mean, T_YZ])
            co, si = float(np.cos(self.orientation)), float(np.sin(self.orientation))
            if layout.kind == "plane":
                return co**2 * d_xi if d_eta is None else co**2 * d_xi + si**2 * d_eta
            return self._rotated(d_xi, d_eta, co, si)

    Crack.__module__ = __name__
    return Crack


def __getattr__(name):
    # The Crack element needs mutext.rotor.assembly; it is built on first use so that the
    # crack formulas above do not depend on the assembly code.
    if name == "Crack":
        cls = _make_crack_class()
        globals()["Crack"] = cls
        return cls
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
