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

The package holds one module per idea: ``_compliance`` (the strip integrals
of :math:`c_{55}` and :math:`c_{44}`), ``_beam`` (the compliance in a beam
model: hinge, cracked element, reduced second moment of area), ``_breathing``
(the breathing laws and their Fourier series), ``_slot`` (gaping notch or
breathing crack from the slot width), ``_element`` (the :class:`Crack`
element) and ``_common`` (the rig's constants and the input checks); every
name is imported from ``mutext.rotor.crack``.

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

from ._beam import (cracked_element_stiffness, cracked_element_stiffness_two_plane, equivalent_reduced_inertia,
                    open_crack_element)
from ._breathing import (BREATHING_ALIASES, BREATHING_LAWS, breathing_fourier, breathing_law, breathing_weights,
                         fixed_frame_stiffness, open_fraction, rotating_frame_stiffness)
from ._common import (MAX_DEPTH_RATIO, RIG_CRACK_DEPTH_RATIO, RIG_CRACK_STATION, RIG_SHAFT_DIAMETER,
                      RIG_YOUNGS_MODULUS)
from ._compliance import COMPONENTS, crack_compliance, crack_compliance_dimensionless, crack_rotational_stiffness
from ._slot import STANDARD_GRAVITY, BreathingChoice, choose_breathing, face_displacement
# the checks and law names the other rotor modules import from here
from ._breathing import _MODELS  # noqa: F401
from ._common import _depth, _matrix, _positive, _scalar, _symbolic  # noqa: F401

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


def __getattr__(name):
    # The Crack element needs mutext.rotor.assembly; it is imported on first use so that the
    # crack formulas do not depend on the assembly code.
    if name == "Crack":
        from ._element import Crack
        globals()["Crack"] = Crack
        return Crack
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
