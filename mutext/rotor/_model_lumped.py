"""The model-file reader for lumped chains: ``[[mass]]``, ``[[spring]]``, ``[[damper]]``,
``[[impedance]]`` and port tables assembled into a :class:`~mutext.rotor.Structure`
(:mod:`mutext.rotor.model`).
"""
from __future__ import annotations

import math
import os

from ..errors import ModelError
from . import units as U
from .assembly import Structure
from .elements import Damper, InputPort, OutputPort, Param, PointMass, Spring, StructuralDamping
from .lumped_elements import Impedance
from ._model_ctx import (_DAMPER, _IMPEDANCE, _MASS, _PORT_LUMPED, _SPRING, _TOP_LUMPED, _array_of_tables, _Ctx,
                         _damping)


def _load_lumped(ctx: _Ctx, doc: dict) -> Structure:
    ctx.check_keys(doc, _TOP_LUMPED, "top level")
    masses = _array_of_tables(ctx, doc, "mass")
    node = {}
    els = []
    for k, t in enumerate(masses, start=1):
        where = f"[[mass]] #{k}"
        ctx.check_keys(t, _MASS, where, required=("name", "mass"))
        name = ctx.string(t, "name", where)
        if name in node or name == "ground":
            raise ctx.err(f"{where}, name", f"'{name}' is used twice or reserved")
        node[name] = k
        m = ctx.number(t, "mass", "mass", where, positive=True)
        els.append(PointMass(k, Param(name, m, "kg", "mass"), name=name))

    def ends(t, where):
        b = t.get("between")
        if not (isinstance(b, list) and len(b) == 2 and all(isinstance(x, str) for x in b)):
            raise ctx.err(f"{where}, between", f"expected two names, e.g. [\"m1\", \"m2\"] or [\"m1\", \"ground\"], "
                          f"got {b!r}")
        out = []
        for x in b:
            if x == "ground":
                out.append(None)
            elif x in node:
                out.append(node[x])
            else:
                raise ctx.err(f"{where}, between", f"unknown mass '{x}' (masses: {', '.join(node)}, ground)")
        if out[0] is None:
            out.reverse()
        if out[0] is None:
            raise ctx.err(f"{where}, between", "both ends are ground")
        if out[0] == out[1]:
            raise ctx.err(f"{where}, between", "both ends are the same mass")
        return out

    for key, spec, cls, field, qty, unit in (("spring", _SPRING, Spring, "stiffness", "stiffness", "N/m"),
                                             ("damper", _DAMPER, Damper, "damping", "damping", "N s/m")):
        for k, t in enumerate(_array_of_tables(ctx, doc, key), start=1):
            where = f"[[{key}]] #{k}"
            ctx.check_keys(t, spec, where, required=("name", "between", field))
            name = ctx.string(t, "name", where)
            a, b = ends(t, where)
            par = Param(name, ctx.number(t, field, qty, where), unit, field)
            els.append(cls(a, b, name=name, **({"k": par} if key == "spring" else {"c": par})))
    for k, t in enumerate(_array_of_tables(ctx, doc, "impedance"), start=1):
        els.append(_impedance(ctx, t, f"[[impedance]] #{k}", node))
    ins, outs = [], []
    for key, lst, cls in (("force", ins, InputPort), ("sensor", outs, OutputPort)):
        for k, t in enumerate(_array_of_tables(ctx, doc, key), start=1):
            where = f"[[{key}]] #{k}"
            ctx.check_keys(t, _PORT_LUMPED, where, required=("name", "mass"))
            m = ctx.string(t, "mass", where)
            if m not in node:
                raise ctx.err(f"{where}, mass", f"unknown mass '{m}' (masses: {', '.join(node)})")
            lst.append(cls(ctx.string(t, "name", where), node[m], "x"))
    damping = _damping(ctx, doc.get("damping"))
    if isinstance(damping, StructuralDamping):
        els.append(damping)
        damping = None
    if not masses:
        raise ctx.err("[[mass]]", "a lumped model needs at least one mass")
    try:
        s = Structure(els, layout="lumped", n_nodes=len(masses), node_names=list(node), inputs=ins,
                      outputs=outs, damping=damping, name=str(doc.get("name", os.path.basename(ctx.source))))
    except ModelError as exc:
        raise ModelError(f"{ctx.source}: {exc}") from None
    s.source = ctx.source
    s.units = ctx.system
    return s


def _impedance(ctx: _Ctx, t, where: str, node: dict) -> Impedance:
    """An ``[[impedance]]`` table: a rational dynamic stiffness to ground at a mass."""
    ctx.check_keys(t, _IMPEDANCE, where, required=("name", "mass", "numerator", "denominator"))
    name = ctx.string(t, "name", where)
    m = ctx.string(t, "mass", where)
    if m not in node:
        raise ctx.err(f"{where}, mass", f"unknown mass '{m}' (masses: {', '.join(node)})")
    coef = {}
    for key in ("numerator", "denominator"):
        c = t[key]
        if not isinstance(c, list) or not c:
            raise ctx.err(f"{where}, {key}", f"expected a non-empty list of numbers (coefficients in descending "
                          f"powers of s), got {c!r}")
        for j, x in enumerate(c):
            if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
                raise ctx.err(f"{where}, {key}[{j}]", f"expected a finite number, got {x!r}")
        coef[key] = [float(x) for x in c]
    # K = numerator/denominator is a stiffness: the numerator carries the unit
    num = [U.to_si(x, "stiffness", ctx.system) for x in coef["numerator"]]
    try:
        return Impedance(node[m], num, coef["denominator"], name=name)
    except ModelError as exc:
        raise ctx.err(where, str(exc)) from None
