r"""Springs, dampers and masses of a lumped chain: changed, or added to ground.

================  ==================================  ===============================================
kind              change of dynamic stiffness          candidates
================  ==================================  ===============================================
``stiffness``     :math:`\theta S`                      every ``[[spring]]`` changed; a spring to ground
                                                      added at every mass that has none
``damping``       :math:`j\omega\theta S`               every ``[[damper]]`` changed; a damper to ground
                                                      added at every mass that has none
``mass``          :math:`-\omega^2\theta S`             every ``[[mass]]`` changed
================  ==================================  ===============================================

:math:`S` is :math:`e_ie_i^T` for an element at mass *i* (or to ground) and
:math:`(e_i-e_j)(e_i-e_j)^T` between masses *i* and *j*; :math:`\theta` is the
change of the element's value (SI), or the value of the added element.  A
change may take the element down to 5 % (10 % for a mass) of its value and up
to ten times it (or ten times the chain's local stiffness at that mass for an
element of value 0).

Written into the model file (:mod:`mutext.rotor.model_writer`): a changed
element gets its new value, an added one a new ``[[spring]]`` or ``[[damper]]``
entry ``between = [mass, "ground"]``.
"""
from __future__ import annotations

import math

import numpy as np

from ...rotor.elements import Damper, PointMass, Spring
from ._base import Hypothesis

KINDS = ("stiffness", "mass", "damping")

#: Order of the change in j w: D(w) = theta S (1, j w, -w^2)[order].
ORDER = {"stiffness": 0, "damping": 1, "mass": 2}

#: (model-file table, key) of each kind.
TABLE = {"stiffness": ("spring", "stiffness"), "damping": ("damper", "damping"), "mass": ("mass", "mass")}


def candidates(model) -> list[Hypothesis]:
    """Every lumped-element hypothesis of a chain ``model``.

    Parameters
    ----------
    model : Structure
        The engineering model (a lumped chain; a rotor gives none).
    """
    lay = model.layout
    n = lay.n_nodes
    names = lay.node_names
    M, C, K, _ = model.matrices()
    out: list[Hypothesis] = []
    grounded = {"stiffness": set(), "damping": set()}
    for el in model.elements:
        if isinstance(el, PointMass):
            i = el.nodes[0]
            m = el.nominal("m")
            out.append(Hypothesis("mass", i, el.name, f"mass {el.name} changed", "kg", False, -0.9 * m, 10 * m,
                                  m, [i - 1], np.ones((1, 1)), 2, parameter=el.param_name("m"), nominal=m))
        elif isinstance(el, (Spring, Damper)):
            kind = "stiffness" if isinstance(el, Spring) else "damping"
            fld = "k" if kind == "stiffness" else "c"
            v = el.nominal(fld)
            unit = "N/m" if kind == "stiffness" else "N s/m"
            what = "spring" if kind == "stiffness" else "damper"
            if len(el.nodes) == 1:
                i = el.nodes[0]
                grounded[kind].add(i)
                dofs, S = [i - 1], np.ones((1, 1))
                where = f"{names[i - 1]}-ground"
            else:
                i, j = el.nodes
                dofs, S = [i - 1, j - 1], np.array([[1.0, -1.0], [-1.0, 1.0]])
                where = f"{names[i - 1]}-{names[j - 1]}"
            scale = v if v > 0 else (float(K[i - 1, i - 1]) if kind == "stiffness"
                                     else 2.0 * math.sqrt(K[i - 1, i - 1] * M[i - 1, i - 1]) * 0.05)
            out.append(Hypothesis(kind, i, el.name, f"{what} {el.name} ({where}) changed", unit, False,
                                  -0.95 * v, 10 * max(v, scale), scale, dofs, S, ORDER[kind],
                                  parameter=el.param_name(fld), nominal=v))
    for i in range(1, n + 1):
        kii, mii = float(K[i - 1, i - 1]), float(M[i - 1, i - 1])
        for kind, unit, scale in (("stiffness", "N/m", kii),
                                  ("damping", "N s/m", 2.0 * math.sqrt(max(kii, 1e-300) * mii) * 0.05)):
            if i in grounded[kind]:
                continue            # the same effect as changing the existing grounded element
            what = "spring" if kind == "stiffness" else "damper"
            name = f"{'k' if kind == 'stiffness' else 'c'}_{names[i - 1]}_ground"
            out.append(Hypothesis(kind, i, name, f"grounded {what} added at {names[i - 1]}", unit, True,
                                  0.0, 10 * scale, scale, [i - 1], np.ones((1, 1)), ORDER[kind],
                                  parameter=f"{name}", nominal=0.0))
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
    table, key = TABLE[h.kind]
    if h.added:
        mf.append(table, {"name": h.element, key: float(finding.value),
                          "between": [model.layout.node_names[h.station - 1], "ground"]}, note, si=True)
        return
    new = finding.new_value if finding.new_value is not None else h.nominal + finding.value
    mf.set(table, lambda t: t.get("name") == h.element, key, float(new), note, si=True)
