r"""A rotor bearing's cross-coupled stiffness: the skew, circulatory part that seals and fluid films add.

==================  ======================================  ==============================================
kind                change of dynamic stiffness             candidates
==================  ======================================  ==============================================
``cross_coupling``  :math:`q S` on the bearing station's     every ``[[bearing]]`` of a two-plane rotor, when
                    :math:`(u, v)`                          a fitted channel crosses the planes
==================  ======================================  ==============================================

with :math:`S = [[0, 1], [-1, 0]]`.  The bearing's stiffness block (force
:math:`f = -K q` on :math:`q = (u, v)`, see
:class:`~mutext.rotor.bearing_element.BearingElement`) gains :math:`k_{xy} = q`,
:math:`k_{yx} = -q`.  The change is frequency-independent and of rank two on
the bearing station's translations, so the exact screen applies as for a
changed bearing stiffness; :math:`q > 0` does positive work on a forward
whirl orbit (the destabilising force of a seal or an oil film), :math:`q < 0`
on a backward one.

One parameter, the skew part, not two.  Of a general pair
:math:`(k_{xy}, k_{yx})` the skew part :math:`q = (k_{xy} - k_{yx})/2` is what
seals and fluid films contribute (the circulatory force that makes a rotor
whirl and that no symmetric stiffness can stand for); the symmetric part
:math:`(k_{xy} + k_{yx})/2` is a conservative coupling -- the principal axes
of an anisotropic bearing turned away from x and y -- a second effect with
its own evidence.  A single signed size also keeps the hypothesis in the
screen's one-parameter path: the exact Gauss-Newton fit of a size of either
sign with its standard uncertainty, the same false-alarm threshold as every
one-parameter kind (the k-parameter fit is for positive parameters).

Reference size and bounds, relative to the bearing's direct stiffness
:math:`k_b` (the smaller of ``stiffness`` and ``stiffness_y``): typical size
:math:`0.1\,k_b` (the scan covers :math:`10^{-4}`-:math:`1` times
:math:`k_b`, either sign), bounds :math:`\pm k_b` -- a circulatory term
larger than the direct stiffness would turn the bearing's force more than
45 degrees away from the displacement, no longer a bearing's coupling.  A
bearing that already holds ``kxy``/``kyx`` is changed by :math:`q` (its
skew part is the nominal value).

Two-plane data only.  On a channel within one plane (x to x) the skew term
enters only through the other plane: in second order (:math:`q^2`) at
standstill, in first order only through the gyroscopic coupling of the two
planes at speed, weak at the rig's 10 Hz -- nearly unidentifiable, and at a
large size its second-order effect can stand in for other changes at the bearing.  It is therefore **not offered**
unless a fitted channel crosses the planes (input in x, output in y or the
reverse: the off-diagonal of the planar FRF matrix, which the rig's
``measure_rotor(..., planes="xy")`` records), where it acts in first order.
(Without data, :func:`mutext.diagnose.hypotheses` does not list it.)

Written into the model file (:mod:`mutext.rotor.model_writer`): the
bearing's ``kxy`` and ``kyx`` set (added when the entry has none), in the
file's units.
"""
from __future__ import annotations

import numpy as np

from ...rotor.elements import BearingElement
from ...rotor.units import from_si
from ._base import Hypothesis

KINDS = ("cross_coupling",)

#: The pattern on (u, v): k_xy = q, k_yx = -q.
SKEW = np.array([[0.0, 1.0], [-1.0, 0.0]])

#: Typical size and bound of q, relative to the bearing's direct stiffness.
REFERENCE_RATIO, BOUND_RATIO = 0.1, 1.0


def _plane(model, spec_or_dof) -> str:
    """The DOF label (``"u"``, ``"v"``, ...) of an input spec ``("port", j)`` / ``("dof", d)`` or of a DOF."""
    lay = model.layout
    if isinstance(spec_or_dof, tuple):
        kind, j = spec_or_dof
        if kind == "port":
            return lay.label(model.inputs[j].direction)
        spec_or_dof = j
    return lay.labels[int(spec_or_dof) % lay.per_node]


def crosses_planes(model, chans) -> bool:
    """Whether a channel of ``chans`` (resolved, :mod:`mutext.diagnose._channels`) drives one bending plane
    and measures the other.

    Parameters
    ----------
    model : Rotor
        The engineering model.
    chans : sequence
        Resolved channels (``in_spec``, ``out_dof``).
    """
    if model.layout.kind != "rotor":
        return False
    return any({_plane(model, c.in_spec), _plane(model, c.out_dof)} == {"u", "v"} for c in chans)


def _cross(el) -> tuple[float, float]:
    return tuple(el.nominal(f) if el.has(f) else 0.0 for f in ("kxy", "kyx"))


def candidates(model, chans, stations=None) -> list[Hypothesis]:
    """A skew cross-coupled stiffness at every bearing of a two-plane rotor, when ``chans`` cross the planes.

    Parameters
    ----------
    model : Rotor
        The engineering model.
    chans : sequence
        The measured channels, resolved on ``model``.
    stations : sequence of int, optional
        Stations to consider (default: all).
    """
    if not crosses_planes(model, chans):
        return []
    lay = model.layout
    out = []
    for el in model.elements:
        if not isinstance(el, BearingElement):
            continue
        s = el.nodes[0]
        if stations is not None and s not in stations:
            continue
        kb = min(el.nominal("k"), el.nominal("kyy") if el.has("kyy") else el.nominal("k"))
        if not kb > 0:
            continue
        kxy, kyx = _cross(el)
        q0 = 0.5 * (kxy - kyx)
        added = kxy == 0.0 and kyx == 0.0
        what = "added at" if added else "changed at"
        out.append(Hypothesis("cross_coupling", s, el.name,
                              f"cross-coupled stiffness (kxy = -kyx) {what} {el.name}", "N/m", added,
                              -BOUND_RATIO * kb, BOUND_RATIO * kb, REFERENCE_RATIO * kb,
                              [lay.dof(s, "u"), lay.dof(s, "v")], SKEW.copy(), 0, parameter=None, nominal=q0))
    return out


def write(mf, finding, model, note: str) -> None:
    """The bearing's ``kxy`` and ``kyx`` into the model file ``mf``: ``kxy + q``, ``kyx - q``.

    Parameters
    ----------
    mf : mutext.rotor.model_writer.ModelFile
        The model file being extended (edited in place).
    finding : Finding
        The accepted finding (its hypothesis and fitted size ``q`` [N/m]).
    model : Rotor
        The engineering model the finding refers to.
    note : str
        Comment written next to the change in the file.
    """
    h = finding.hypothesis
    q = float(finding.value)
    el = next(e for e in model.elements if isinstance(e, BearingElement) and e.name == h.element)
    kxy, kyx = _cross(el)
    units = str(mf.doc.get("units", "SI"))

    def select(t):
        return str(t.get("name") or f"bearing{t.get('station')}") == h.element
    mf.set("bearing", select, "kxy", from_si(kxy + q, "stiffness", units), note)
    mf.set("bearing", select, "kyx", from_si(kyx - q, "stiffness", units), note)
