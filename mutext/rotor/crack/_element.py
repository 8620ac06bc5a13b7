r"""The crack element of an assembled rotor: :class:`Crack`.

The element adds the cracked-minus-intact stiffness of its host shaft
element (:class:`mutext.rotor.assembly.ShaftFlexibility`), with the depth
ratio as a model parameter; a breathing crack's time-invariant model holds
the stiffness averaged over one revolution.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from ...errors import ModelError
from ..assembly import Rotor, ShaftFlexibility
from ..element import Element
from ..shaft_element import T_XZ, T_YZ
from ._breathing import breathing_fourier, breathing_law
from ._common import MAX_DEPTH_RATIO
from ._compliance import crack_compliance


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


# the public home of the class (as before the split into modules)
Crack.__module__ = "mutext.rotor.crack"
