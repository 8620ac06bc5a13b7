r"""A rotor's bearings changed, and springs, dampers and masses added at its stations.

================  ===================================  ==============================================
kind              change of dynamic stiffness           candidates
================  ===================================  ==============================================
``bearing``       :math:`\theta S` (stiffness) or        every ``[[bearing]]``: its stiffness or its
                  :math:`j\omega\theta S` (damping)     damping changed
``stiffness``     :math:`\theta S`                       a spring to ground added at a station without
                                                       a bearing
``damping``       :math:`j\omega\theta S`                a damper to ground added there
``mass``          :math:`-\omega^2\theta S`              a point mass added there
================  ===================================  ==============================================

:math:`S` is the identity on the station's translations (``u`` and, for a
rotor in two planes, ``v``): the added element acts alike in both planes.
Reference sizes: the softest bearing's stiffness (or :math:`10^{-3}` of the
shaft's stiffest diagonal term), 2 % of critical damping at the first natural
frequency, a tenth of the rotor's mass.

Written into the model file (:mod:`mutext.rotor.model_writer`): a bearing's
new value in its ``[[bearing]]`` entry; an added spring or damper as a new
``[[bearing]]`` entry (the other value 0), an added mass as a ``[[disk]]``.
"""
from __future__ import annotations

import numpy as np

from ...rotor.elements import BearingElement
from ._base import Hypothesis

KINDS = ("bearing", "stiffness", "damping", "mass")


def candidates(model, stations=None) -> list[Hypothesis]:
    """Every bearing and added-element hypothesis of a rotor ``model`` (at ``stations``, default all).

    Parameters
    ----------
    model : Rotor
        The engineering model (a rotor).
    stations : sequence of int, optional
        Stations to consider (default: all).
    """
    lay = model.layout
    M, C, K, _ = model.matrices()
    out: list[Hypothesis] = []
    bearings = {el.nodes[0]: el for el in model.elements if isinstance(el, BearingElement)}
    total_mass = float(np.sum(M[0::4, 0::4]))     # consistent mass: the whole x-x block
    # reference stiffness and damping: the softest bearing (or 1e-3 of the shaft's local stiffness),
    # and 2 % of critical at the first natural frequency
    k_ref = min((el.nominal("k") for el in bearings.values()), default=1e-3 * float(np.max(np.diag(K))))
    w1 = 2 * np.pi * float(model.natural_frequencies(n=1)[0])
    c_ref = 0.02 * k_ref / w1
    stations = range(1, lay.n_nodes + 1) if stations is None else stations
    two = lay.kind == "rotor"
    for s in stations:
        dofs = [lay.dof(s, "u")] + ([lay.dof(s, "v")] if two else [])
        S = np.eye(len(dofs))
        if s in bearings:
            el = bearings[s]
            kb, cb = el.nominal("k"), el.nominal("c")
            out.append(Hypothesis("bearing", s, el.name, f"stiffness of {el.name} changed", "N/m", False,
                                  -0.95 * kb, 10 * kb, kb, dofs, S, 0, parameter=el.param_name("k"), nominal=kb))
            out.append(Hypothesis("bearing", s, el.name, f"damping of {el.name} changed", "N s/m",
                                  cb == 0.0, -0.95 * cb if cb > 0 else 0.0, 1000 * c_ref, max(cb, c_ref), dofs, S,
                                  1, parameter=el.param_name("c"), nominal=cb))
            continue
        out.append(Hypothesis("stiffness", s, f"k_s{s}", f"grounded spring added at station {s}", "N/m", True,
                              0.0, 100 * k_ref, k_ref, dofs, S, 0, parameter=f"k_s{s}.k"))
        out.append(Hypothesis("mass", s, f"m_s{s}", f"point mass added at station {s}", "kg", True,
                              0.0, total_mass, 0.1 * total_mass, dofs, S, 2, parameter=f"m_s{s}.m"))
        out.append(Hypothesis("damping", s, f"c_s{s}", f"grounded damper added at station {s}", "N s/m", True,
                              0.0, 1000 * c_ref, c_ref, dofs, S, 1, parameter=f"c_s{s}.c"))
    return out


def write(mf, finding, model, note: str) -> None:
    """Write ``finding`` into the model file ``mf`` (:class:`~mutext.rotor.model_writer.ModelFile`).

    Parameters
    ----------
    mf : mutext.rotor.model_writer.ModelFile
        The model file being extended (edited in place).
    finding : Finding
        The accepted finding (its hypothesis and fitted size).
    model : Structure or Rotor
        The engineering model the finding refers to.
    note : str
        Comment written next to the change in the file.
    """
    h = finding.hypothesis
    v = float(finding.value)
    if h.kind == "bearing":
        key = "stiffness" if h.order == 0 else "damping"
        new = finding.new_value if finding.new_value is not None else h.nominal + v
        mf.set("bearing", lambda t: t.get("station") == h.station, key, float(new), note, si=True)
    elif h.kind == "stiffness":
        mf.append("bearing", {"name": h.element, "station": h.station, "stiffness": v, "damping": 0.0}, note,
                  si=True)
    elif h.kind == "damping":
        mf.append("bearing", {"name": h.element, "station": h.station, "stiffness": 0.0, "damping": v}, note,
                  si=True)
    elif h.kind == "mass":
        mf.append("disk", {"name": h.element, "station": h.station, "mass": v}, note, si=True)
    else:
        raise ValueError(f"not a rotor element kind: {h.kind}")
