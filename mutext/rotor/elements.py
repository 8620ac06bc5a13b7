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

:class:`StructuralDamping` (here) is the proportional damping of a model
file's ``[damping] alpha, beta``: :math:`\alpha M` and :math:`\beta` times the
stiffness of the structure's own members, not of its connections to ground.

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

import casadi as ca

from .bearing_element import BearingElement
from .disk_element import DiskElement, PointMass
from .element import Element, InputPort, Layout, OutputPort, Param, ParameterSet, _positive
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
    "PointMass", "Spring", "Damper", "StructuralDamping",
    "section_properties", "cowper_shear_coefficient", "timoshenko_plane_matrices",
    "timoshenko_shape_functions", "plane_to_rotor",
]



class StructuralDamping(Element):
    r"""Proportional damping of a structure's own members: :math:`C \mathrel{+}= \alpha M + \beta K_s`.

    ``alpha`` [1/s] multiplies the whole mass matrix.  ``beta`` [s] multiplies
    :math:`K_s`, the stiffness of the structure's *members*: every element
    except the connections to ground -- bearings, exciters (their negative
    stiffness) and springs with one end on the ground.  Those carry only the
    damping they are given (a bearing's ``damping``, a ``[[damper]]``), so a
    grounded spring or bearing added to a model (as :mod:`mutext.diagnose`
    adds one to the model file) leaves the damping matrix as it was.  Shaft
    elements, cracks (they lower the shaft's stiffness, and its damping with
    it) and springs between two masses are members.

    This is what a model file's ``[damping] alpha, beta`` builds
    (:mod:`mutext.rotor.model`); :class:`mutext.rotor.assembly.ProportionalDamping`
    is the plain :math:`\alpha M + \beta K` of the whole assembled model.  The
    element spans all nodes and reads the other elements of its structure
    when bound; its parameters are ``"<name>.alpha"`` and ``"<name>.beta"``
    (``"damping.alpha"``, ``"damping.beta"``).

    Parameters
    ----------
    alpha : float or Param, optional
        Mass-proportional coefficient [1/s].
    beta : float or Param, optional
        Coefficient of the members' stiffness [s].
    name : str, optional
        Name of the element and prefix of its parameters.
    """
    KIND = "damping"
    FIELDS = {"alpha": ("1/s", "mass-proportional damping coefficient"),
              "beta": ("s", "stiffness-proportional damping coefficient of the structure's members")}

    def __init__(self, alpha=0.0, beta=0.0, *, name: str = "damping"):
        super().__init__((1,), name, alpha=alpha, beta=beta)
        _positive(self, "alpha", "beta", allow_zero=True)
        self.members: list = []

    def bind(self, structure):
        """Collect the other elements of ``structure`` (its members are read when the matrix is built).

        Parameters
        ----------
        structure : Structure
            The structure the element is part of.
        """
        self.members = [el for el in structure.elements if el is not self]

    @staticmethod
    def grounded(el) -> bool:
        """True for a connection to ground (no stiffness-proportional damping).

        Parameters
        ----------
        el : Element
            An element of the structure.
        """
        return isinstance(el, (BearingElement, ExciterElement)) or (isinstance(el, Spring) and len(el.nodes) == 1)

    def dofs(self, layout):
        return list(range(layout.ndof))

    def damping_matrix(self, p, layout):
        n = layout.ndof
        C = ca.SX(n, n)
        a, b = self.sym(p, "alpha"), self.sym(p, "beta")
        for el in self.members:
            idx = el.dofs(layout)
            Me = el.mass_matrix(p, layout)
            if Me is not None:
                C[idx, idx] = C[idx, idx] + a * ca.SX(Me)
            if not self.grounded(el):
                Ke = el.stiffness_matrix(p, layout)
                if Ke is not None:
                    C[idx, idx] = C[idx, idx] + b * ca.SX(Ke)
        return C
