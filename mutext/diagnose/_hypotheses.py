"""Hypotheses of the form *kind at location*: what each changes in the model and how large it may be."""
from __future__ import annotations

import logging
import math
import os

import casadi as ca
import numpy as np

from ..rotor.crack import Crack
from ..rotor.elements import BearingElement, Damper, ParameterSet, PointMass, Spring
from ..rotor.model import load_model
from ._channels import _resolve
from .faults import channel as _channel
from .faults import structure as _structure
from .faults._base import Hypothesis

log = logging.getLogger("mutext.diagnose")

#: Kinds of finding (the ``kind`` field of :class:`~mutext.diagnose.Finding`).
KINDS = ("stiffness", "mass", "damping", "crack", "bearing") + _channel.KINDS + _structure.KINDS + ("none",)

_ORDER = {"stiffness": 0, "damping": 1, "mass": 2}      # D(w) = S * (1, j w, -w^2)[order]


def _lumped_hypotheses(model) -> list[Hypothesis]:
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
                                  -0.95 * v, 10 * max(v, scale), scale, dofs, S, _ORDER[kind],
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
                                  0.0, 10 * scale, scale, [i - 1], np.ones((1, 1)), _ORDER[kind],
                                  parameter=f"{name}", nominal=0.0))
    return out


def _rotor_hypotheses(model, stations=None) -> list[Hypothesis]:
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


def hypotheses(model, frfs=None, *, stations=None) -> list[Hypothesis]:
    """The hypotheses :func:`diagnose` tests on ``model`` (given the measured channels ``frfs``)."""
    if isinstance(model, (str, os.PathLike)):
        model = load_model(model)
    kind = model.layout.kind
    hyps = _lumped_hypotheses(model) if kind == "lumped" else _rotor_hypotheses(model, stations)
    if kind != "lumped":
        hyps += _crack_hypotheses(model, stations)
    if frfs is not None:
        chans, _ = _resolve(model, list(frfs), "FRF")
        hyps += _channel.candidates(model, chans)
    return hyps


def _crack_hypotheses(model, stations=None) -> list[Hypothesis]:
    """A crack in shaft element s (between stations s and s+1), depth ratio in [0, 0.5]."""
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
