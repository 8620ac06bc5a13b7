r"""Finite elements of a rotor (and of lumped chains), as CasADi expressions.

One module per physical part, in the style of ROSS; this module gathers
their public names so that ``from mutext.rotor.elements import ...`` reaches
every element:

``element``
    :class:`Param`, :class:`ParameterSet`, :class:`Layout`, the ports and the
    :class:`Element` interface every part implements.
``shaft_element``
    :class:`ShaftElement` (Timoshenko beam), its section properties, plane
    matrices and shape functions.
``disk_element``
    :class:`DiskElement` (rigid lumped disk) and :class:`PointMass`.
``bearing_element``
    :class:`BearingElement` (linear springs and dampers to ground).
``exciter_element``
    :class:`ExciterElement` (magnetic actuator: force per ampere and negative
    stiffness).
``lumped_elements``
    :class:`Spring` and :class:`Damper` of lumped mass-spring-damper chains.

The crack element lives with its fracture mechanics in
:mod:`mutext.rotor.crack`.  :class:`mutext.rotor.assembly.Structure`
assembles the elements.

Every numeric field of an element is a *parameter*: a plain number becomes a
parameter private to the element (named ``"<element>.<field>"``, e.g.
``"shaft3.L"``); a :class:`Param` can be shared by several elements (e.g. one
Young's modulus ``"E"`` for the whole shaft).  Element matrices are CasADi
``SX`` expressions of the parameter symbols, so that the assembled matrices
are functions :math:`M(p), C(p), K(p), G(p)` with exact derivatives.

Degrees of freedom (the *layout*)
---------------------------------
``"rotor"`` (two bending planes, 4 DOF per station)
    :math:`(u, v, \theta, \psi)`: displacement along x and y, rotation about x
    and about y.  With the shaft along z, the slopes are
    :math:`\partial u/\partial z = \psi` and :math:`\partial v/\partial z = -\theta`
    (right-handed rotations, as in Friswell et al. 2010, ch. 5).  The rotor spins
    at :math:`\Omega` about +z.
``"plane"`` (one bending plane, 2 DOF per station)
    :math:`(u, \psi)`: the x-z plane of the rotor layout.  No gyroscopic effect.
``"lumped"`` (1 DOF per node)
    :math:`x`: translation of a lumped mass.

Equation of motion (SI: m, rad, kg, N, N m)

.. math::
    M\ddot q + (C + \Omega G)\dot q + K q = f .

References
----------
.. [Fri] M. I. Friswell, J. E. T. Penny, S. D. Garvey and A. W. Lees,
   *Dynamics of Rotating Machines*, Cambridge University Press, 2010, ch. 5
   (disks, bearings, Timoshenko shaft elements, example 5.9.1).
"""
from __future__ import annotations

from .bearing_element import BearingElement
from .disk_element import DiskElement, PointMass
from .element import Element, InputPort, Layout, OutputPort, Param, ParameterSet
from .exciter_element import ExciterElement
from .lumped_elements import Damper, Spring
from .shaft_element import (  # noqa: F401  (the plane maps, used by the crack element)
                            T_XZ,
                            T_YZ,
                            ShaftElement,
                            cowper_shear_coefficient,
                            plane_to_rotor,
                            section_properties,
                            timoshenko_plane_matrices,
                            timoshenko_shape_functions,
)

__all__ = [
    "Param", "ParameterSet", "Layout", "InputPort", "OutputPort", "Element",
    "ShaftElement", "DiskElement", "BearingElement", "ExciterElement",
    "PointMass", "Spring", "Damper",
    "section_properties", "cowper_shear_coefficient", "timoshenko_plane_matrices",
    "timoshenko_shape_functions", "plane_to_rotor",
]

