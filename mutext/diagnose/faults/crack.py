r"""An open crack in a shaft element: the exact stiffness change of :class:`mutext.rotor.crack.Crack`.

================  ======================================================  =================================
kind              change of dynamic stiffness                             candidates
================  ======================================================  =================================
``crack``         :math:`\Delta K(a/D)` of the crack element on the       every shaft element (station s
                  element's DOFs, nonlinear in the depth ratio            to s+1); depth ratio in [0, 0.5]
================  ======================================================  =================================

The change is built once per element as a CasADi function of the model's
parameters and the depth ratio and evaluated at the model's values.  The
hypothesis is the package's default crack: open, facing :math:`x` (the
measured direction), with both bending compliances (:math:`c_{55}` across
the crack edge, :math:`c_{44}` along it).  Written into the model file as a
``[[crack]]`` entry (station, depth ratio), which reads back as the same
crack.
"""
from __future__ import annotations

import logging

import casadi as ca
import numpy as np

from ...rotor.crack import Crack
from ...rotor.elements import ParameterSet
from ._base import Hypothesis

log = logging.getLogger("mutext.diagnose")

KINDS = ("crack",)


def candidates(model, stations=None) -> list[Hypothesis]:
    """A crack in shaft element s (between stations s and s+1), depth ratio in [0, 0.5].

    Parameters
    ----------
    model : Rotor
        The engineering model (a rotor).
    stations : sequence of int, optional
        Stations to consider (default: all).
    """
    lay = model.layout
    out = []
    shafts = {el.nodes[0]: el for el in model.elements if type(el).__name__ == "ShaftElement"}
    stations = range(1, lay.n_nodes) if stations is None else [s for s in stations if s < lay.n_nodes]
    p = model.p
    pnames = model.parameter_names
    for s in stations:
        if s not in shafts:
            continue
        cr = Crack(station=s, depth_ratio=0.0, name=f"crack{s}")
        # the crack's stiffness change, as a function of the model's parameters and its depth
        try:
            cr.bind(model)
            cr.declare(ParameterSet())
            a = ca.SX.sym("a")
            syms = {n: p[i] for i, n in enumerate(pnames)}
            syms[cr.param_name("depth_ratio")] = a
            dK = cr.stiffness_matrix(syms, lay)
        except Exception as exc:  # pragma: no cover - reported, not fatal
            log.debug("no crack hypothesis at station %s: %s", s, exc)
            continue
        dofs = cr.dofs(lay)
        fun = ca.Function(f"dK_crack{s}", [p, a], [dK])
        v0 = model.values()
        out.append(Hypothesis("crack", s, f"crack{s}", f"open crack in the shaft element {s}-{s + 1}", "1", True,
                              0.0, 0.5, 0.1, list(dofs), None, 0, parameter=f"crack{s}.depth_ratio",
                              crack=lambda depth, f=fun, v=v0: np.asarray(f(v, depth).full())))
    return out


def write(mf, finding, model, note: str) -> None:
    """Write the crack into the model file ``mf`` (:class:`~mutext.rotor.model_writer.ModelFile`).

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
    mf.append("crack", {"station": finding.hypothesis.station, "depth_ratio": float(finding.value)}, note, si=True)
