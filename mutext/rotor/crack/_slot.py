r"""Gaping notch or breathing crack: the faces' movement under the shaft's weight.

:func:`choose_breathing` compares the slot width with the movement of the
faces at the crack mouth (:func:`face_displacement`) under the static
bending moment of the rotor's weight (a model file's ``breathing = "auto"``).
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from ...errors import ModelError
from ._breathing import breathing_law
from ._common import _scalar
from ._compliance import crack_compliance

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
    from ..shaft_element import T_YZ
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
