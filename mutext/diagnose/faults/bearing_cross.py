r"""A rotor bearing's cross-coupled stiffness: the skew, circulatory part that seals and fluid films add.

==================  ======================================  ==============================================
kind                change of dynamic stiffness             candidates
==================  ======================================  ==============================================
``cross_coupling``  :math:`q S` on the bearing station's     every ``[[bearing]]`` of a two-plane rotor
                    :math:`(u, v)`
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

Which data. The hypothesis is offered on every two-plane rotor, whatever the
channels, and the screen's test decides (the same Bonferroni threshold as
every hypothesis; two more hypotheses barely move it). Across the planes (x
in, y out or the reverse: the off-diagonal of the planar FRF matrix that
``measure_rotor(..., planes="xy")`` records) :math:`q` acts in first order.
Within one plane (x to x) it acts only through the other plane: in second
order (:math:`q^2`) at standstill (seen, if at all, at resonances, where the
modes' damping force is small against it); at speed in first order through the
gyroscopic coupling, at the resonances of the split whirl pairs. Measured on
the thesis rotor at 10 Hz (1 % noise, 20-225 Hz, the plain rotor of the tests
as data, :math:`q = 2\cdot 10^5` N/m at bearing 29): the planar channels 12 ->
13 find it at 29 with a standard uncertainty of 950 N/m; x-only fitted
channels (x13, x6, x24) find the kind and the size (:math:`2.01\cdot 10^5 \pm
9.3\cdot 10^3` N/m) but cannot tell bearing 2 from bearing 29
(:math:`\Delta\chi^2` 463.5 and 463.8); on x-only data without the effect its
:math:`\Delta\chi^2` is 0, on data of bearing 29 softened by 30 % at most
3.9e3 against 2.2e5 for the right hypothesis.

Written into the model file (:mod:`mutext.rotor.model_writer`): the
bearing's ``kxy`` and ``kyx`` set (added when the entry has none), in the
file's units.  The size is not refitted on the extended model (no single
model parameter holds it; ``parameter`` is None): nothing there differs from
the screen's exact fit, since modal damping follows the symmetric part of K,
which a skew :math:`q` leaves unchanged.
"""
from __future__ import annotations

import numpy as np

from ...rotor.elements import BearingElement
from ._base import Hypothesis

KINDS = ("cross_coupling",)

#: The pattern on (u, v): k_xy = q, k_yx = -q.
SKEW = np.array([[0.0, 1.0], [-1.0, 0.0]])

#: Typical size and bound of q, relative to the bearing's direct stiffness.
REFERENCE_RATIO, BOUND_RATIO = 0.1, 1.0


def _cross(el) -> tuple[float, float]:
    return tuple(el.nominal(f) if el.has(f) else 0.0 for f in ("kxy", "kyx"))


def candidates(model, stations=None) -> list[Hypothesis]:
    """A skew cross-coupled stiffness at every bearing of a two-plane rotor ``model`` (none on one plane).

    Parameters
    ----------
    model : Rotor
        The engineering model.
    stations : sequence of int, optional
        Stations to consider (default: all).
    """
    if model.layout.kind != "rotor":
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

    def select(t):
        return str(t.get("name") or f"bearing{t.get('station')}") == h.element
    mf.set("bearing", select, "kxy", kxy + q, note, si=True)
    mf.set("bearing", select, "kyx", kyx - q, note, si=True)
