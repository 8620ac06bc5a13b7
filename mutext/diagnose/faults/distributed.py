r"""A stiffness change shared by a run of consecutive springs of a chain (a distributed loss).

========================  ========================================================  ====================
kind                      change of dynamic stiffness                               candidates
========================  ========================================================  ====================
``distributed_stiffness``  :math:`\theta \sum_{s \in \text{run}} k_s S_s`              every run of two or
                                                                                     more consecutive
                                                                                     springs
========================  ========================================================  ====================

Every spring :math:`s` of the run keeps its share: its stiffness becomes
:math:`(1 + \theta) k_s` (a loss is :math:`\theta < 0`, e.g. a temperature or
an ageing that softens a whole storey range alike).  :math:`S_s` is the
spring's pattern (:mod:`mutext.diagnose.faults.lumped`); the sum is one real
matrix, so the hypothesis has one parameter and the exact screen of the
local kinds applies.  The run is the location: springs ordered along the
chain (a spring between masses *i* and *j* at :math:`(i + j)/2`, ground
taken as the end of the chain the spring is at), consecutive when
neighbours share a mass; a run of one spring is the spring's own change.
Range: :math:`\theta \in [-0.95, 2]`.

Written into the model file (:mod:`mutext.rotor.model_writer`): every spring
of the run gets its new stiffness.
"""
from __future__ import annotations

import numpy as np

from ...rotor.elements import Spring
from ._base import Hypothesis

KINDS = ("distributed_stiffness",)

#: Range of the common relative change.
RANGE = (-0.95, 2.0)


def runs(model) -> list:
    """Runs of two or more consecutive springs of a chain, each a list of Spring elements in chain order.

    Parameters
    ----------
    model : Structure
        A lumped chain.
    """
    n = model.layout.n_nodes
    springs = [el for el in model.elements if isinstance(el, Spring)]

    def ends(el):
        if len(el.nodes) == 1:                 # to ground: at the chain's end nearer the mass
            i = el.nodes[0]
            return (i, 0 if i <= n / 2 else n + 1)
        return tuple(el.nodes)

    order = sorted(springs, key=lambda el: (sum(ends(el)) / 2, el.name))
    segments, cur = [], []
    for el in order:
        if cur and not set(ends(cur[-1])) & set(ends(el)):
            segments.append(cur)
            cur = []
        cur.append(el)
    if cur:
        segments.append(cur)
    out = []
    for seg in segments:
        for a in range(len(seg)):
            for b in range(a + 2, len(seg) + 1):
                out.append(seg[a:b])
    return out


def candidates(model) -> list[Hypothesis]:
    """A common relative stiffness change of every run of consecutive springs (lumped chains).

    Parameters
    ----------
    model : Structure
        The engineering model (a lumped chain; a rotor gives none).
    """
    lay = model.layout
    if lay.kind != "lumped":
        return []
    out = []
    for run in runs(model):
        dofs = sorted({i - 1 for el in run for i in el.nodes})
        P = np.zeros((len(dofs), len(dofs)))
        for el in run:
            k = el.nominal("k")
            p = [dofs.index(i - 1) for i in el.nodes]
            if len(p) == 1:
                P[p[0], p[0]] += k
            else:
                a, b = p
                P[np.ix_([a, b], [a, b])] += k * np.array([[1.0, -1.0], [-1.0, 1.0]])
        names = [el.name for el in run]
        station = min(i for el in run for i in el.nodes)
        out.append(Hypothesis("distributed_stiffness", station, f"{names[0]}..{names[-1]}",
                              f"springs {', '.join(names)} changed by a common fraction", "1", False, RANGE[0],
                              RANGE[1], 0.05, dofs, P, 0, parameter=None, nominal=0.0,
                              run=tuple(names)))
    return out


def write(mf, finding, model, note: str) -> None:
    """Every spring of the run at ``(1 + theta)`` times its stiffness in the model file ``mf``.

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
    f = 1.0 + float(finding.value)
    for name in h.run:
        el = next(e for e in model.elements if isinstance(e, Spring) and e.name == name)
        mf.set("spring", lambda t, name=name: t.get("name") == name, "stiffness", f * el.nominal("k"), note,
               si=True)
