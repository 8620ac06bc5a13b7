"""The model-file reader for rotors: a station table (a file or inline ``[[station]]`` rows)
turned into shaft elements (:func:`rotor_from_table`), and the disks, bearings, exciters, ports
and cracks of the file, read one table kind at a time (:mod:`mutext.rotor.model`).
"""
from __future__ import annotations

import os

from ..errors import ModelError
from . import units as U
from .assembly import Rotor
from .elements import (BearingElement, DiskElement, ExciterElement, InputPort, OutputPort, Param, ShaftElement,
                       StructuralDamping)
from .table import Station, StationTable, read_station_table
from ._model_ctx import (_BEARING, _DISK, _EXCITER, _PORT_ROTOR, _SHAFT, _STATION, _TOP_ROTOR, DEFAULT_POISSON_RATIO,
                         _array_of_tables, _Ctx, _damping)


def _uniform(values):
    return all(v == values[0] for v in values)


def rotor_from_table(table: StationTable, *, poisson_ratio: float | None = DEFAULT_POISSON_RATIO,
                     shear_modulus: float | None = None, ports_from_flags: bool = True,
                     extra_elements=(), inputs=(), outputs=(), **rotor_kw) -> Rotor:
    """A :class:`Rotor` from a station table (SI) plus extra elements.

    Shaft element *s* joins stations *s* and *s+1* with the length, diameters,
    modulus and density of row *s*; a row with added mass or inertia becomes
    a :class:`DiskElement` ``disk<s>``.  Young's modulus and density are one
    shared parameter each (``"E"``, ``"rho"``) when every shaft element has
    the same value, else one per element.  The table has no shear data:
    ``poisson_ratio`` (shared parameter ``"nu"``, default 0.3, steel) or
    ``shear_modulus`` (``"G"`` [Pa]) supplies it.

    With ``ports_from_flags`` the flags become ports in the x-z plane:
    translational input -> force ``F<s>`` [N], translational output ->
    displacement ``x<s>`` [m], rotational input -> moment ``M<s>`` [N m]
    about y, rotational output -> rotation ``psi<s>`` [rad].

    Parameters
    ----------
    table : StationTable
        Station rows in SI units (lengths [m], masses [kg], inertias
        [kg m^2], modulus [Pa], density [kg/m^3]).
    poisson_ratio : float or None, optional
        Poisson's ratio that gives the shear modulus G = E / (2 (1 + nu))
        (shared parameter ``"nu"``); ``None`` when ``shear_modulus`` is given.
    shear_modulus : float, optional
        Shear modulus [Pa] (shared parameter ``"G"``), instead of ``poisson_ratio``.
    ports_from_flags : bool, optional
        Turn the table's input/output flags into ports (above).
    extra_elements : sequence of Element, optional
        Bearings, exciters, cracks or other elements added to the shaft and disks.
    inputs, outputs : sequence of InputPort / OutputPort, optional
        Ports added to those of the flags.
    **rotor_kw
        Passed to :class:`Rotor` (e.g. ``speed``, ``damping``, ``name``).

    Returns
    -------
    Rotor
    """
    st = table.stations
    if (poisson_ratio is None) == (shear_modulus is None):
        raise ModelError(f"{table.source}: give exactly one of poisson_ratio and shear_modulus")
    rows = st[:-1]
    Es, rhos = [s.youngs_modulus for s in rows], [s.density for s in rows]
    E = Param("E", Es[0], "Pa", "Young's modulus") if _uniform(Es) else None
    rho = Param("rho", rhos[0], "kg/m^3", "mass density") if _uniform(rhos) else None
    shear = ({"nu": Param("nu", poisson_ratio, "1", "Poisson's ratio")} if shear_modulus is None
             else {"G": Param("G", shear_modulus, "Pa", "shear modulus")})
    els = []
    for s in rows:
        els.append(ShaftElement(s.number, s.length, s.outer_diameter, s.inner_diameter,
                                E=E if E is not None else s.youngs_modulus,
                                rho=rho if rho is not None else s.density, **shear))
    for s in st:
        if s.added_mass > 0 or s.added_polar_inertia > 0 or s.added_transverse_inertia > 0:
            els.append(DiskElement(s.number, s.added_mass, s.added_polar_inertia, s.added_transverse_inertia))
    ins, outs = [], []
    if ports_from_flags:
        for s in st:
            if s.translational_input:
                ins.append(InputPort(f"F{s.number}", s.number, "u"))
            if s.rotational_input:
                ins.append(InputPort(f"M{s.number}", s.number, "psi", unit="N m"))
            if s.translational_output:
                outs.append(OutputPort(f"x{s.number}", s.number, "u"))
            if s.rotational_output:
                outs.append(OutputPort(f"psi{s.number}", s.number, "psi", unit="rad"))
    return Rotor(els + list(extra_elements), n_stations=len(st), inputs=ins + list(inputs),
                 outputs=outs + list(outputs), **rotor_kw)


def _inline_stations(ctx: _Ctx, rows) -> tuple[StationTable, dict]:
    stations, shear = [], {}
    for k, row in enumerate(rows, start=1):
        where = f"[[station]] #{k}"
        ctx.check_keys(row, _STATION, where)
        last = k == len(rows)
        length = ctx.number(row, "length", "length", where, default=0.0 if last else None)
        if last and length != 0:
            raise ctx.err(f"{where}, length", "the last station must have length 0 (or none): a length is "
                          "that of the element to the next station")
        if not last and length <= 0:
            raise ctx.err(f"{where}, length", f"must be positive, got {row['length']!r}")
        do = ctx.number(row, "outer_diameter", "length", where, default=0.0 if last else None,
                        positive=not last)
        di = ctx.number(row, "inner_diameter", "length", where, default=0.0)
        if di >= do and do > 0:
            raise ctx.err(f"{where}, inner_diameter", "must be smaller than outer_diameter")
        E = ctx.number(row, "youngs_modulus", "modulus", where, default=1.0 if last else None, positive=True)
        rho = ctx.number(row, "density", "density", where, default=1.0 if last else None, positive=True)
        if "shear_modulus" in row:
            shear[k] = ctx.number(row, "shear_modulus", "modulus", where, positive=True)
        flags = {f: ctx.boolean(row, key, where) for f, key in (
            ("translational_input", "force_input"), ("translational_output", "displacement_output"),
            ("rotational_input", "moment_input"), ("rotational_output", "rotation_output"))}
        stations.append(Station(
            number=k, added_mass=ctx.number(row, "added_mass", "mass", where, default=0.0),
            length=length, outer_diameter=do, inner_diameter=di,
            added_polar_inertia=ctx.number(row, "added_polar_inertia", "inertia", where, default=0.0),
            added_transverse_inertia=ctx.number(row, "added_transverse_inertia", "inertia", where, default=0.0),
            youngs_modulus=E, density=rho, source=f"{ctx.source} {where}", **flags))
    if len(stations) < 2:
        raise ctx.err("[[station]]", f"a rotor needs at least 2 stations, found {len(stations)}")
    return StationTable(stations, ctx.source), shear


def _load_rotor(ctx: _Ctx, doc: dict, base_dir: str, station_table=None) -> Rotor:
    ctx.check_keys(doc, _TOP_ROTOR, "top level")
    shaft = doc.get("shaft", {})
    ctx.check_keys(shaft, _SHAFT, "[shaft]")
    table, per_station_G = _stations(ctx, doc, shaft, base_dir, station_table)
    n = len(table)
    G, nu = _shaft_material(ctx, shaft, per_station_G, n)
    ports = ctx.boolean(shaft, "ports_from_flags", "[shaft]", default=True)
    planes, speed = _planes_and_speed(ctx, doc)

    extra = _disks(ctx, doc, n)
    extra += _bearings(ctx, doc, n, planes)
    extra += _exciters(ctx, doc, n, planes)
    ins, outs = _rotor_ports(ctx, doc, n, planes)
    auto = _cracks(ctx, doc, n, extra)
    damping = _damping(ctx, doc.get("damping"))
    if isinstance(damping, StructuralDamping):          # an element: it knows which elements are members
        extra.append(damping)
        damping = None

    def build(elements):
        try:
            return rotor_from_table(table, poisson_ratio=nu, shear_modulus=G, ports_from_flags=ports,
                                    extra_elements=elements, inputs=ins, outputs=outs, planes=planes, speed=speed,
                                    damping=damping, name=str(doc.get("name", os.path.basename(ctx.source))))
        except ModelError as exc:
            raise ModelError(f"{ctx.source}: {exc}") from None

    choices = _auto_breathing(ctx, auto, extra, build)
    rotor = build(extra)
    rotor.breathing_choices = choices
    rotor.table = table
    rotor.source = ctx.source
    rotor.units = ctx.system
    return rotor


def _stations(ctx: _Ctx, doc: dict, shaft: dict, base_dir: str, station_table) -> tuple[StationTable, dict]:
    """The station table (a file given to the loader, the file of ``[shaft]``, or inline
    ``[[station]]`` rows) and the shear moduli given per inline station."""
    if station_table is not None:
        table = read_station_table(station_table)
        per_station_G = {}
    elif "station_table" in shaft:
        if "station" in doc:
            raise ctx.err("[shaft]", "give either station_table or [[station]] rows, not both")
        rel = ctx.string(shaft, "station_table", "[shaft]")
        path = rel if os.path.isabs(rel) else os.path.join(base_dir, rel)
        if not os.path.exists(path):
            raise ctx.err("[shaft], station_table", f"file '{rel}' not found (looked for {path})")
        table = read_station_table(path)
        per_station_G = {}
    elif "station" in doc:
        table, per_station_G = _inline_stations(ctx, _array_of_tables(ctx, doc, "station"))
    else:
        raise ctx.err("[shaft]", "missing 'station_table' (or inline [[station]] rows)")
    return table, per_station_G


def _shaft_material(ctx: _Ctx, shaft: dict, per_station_G: dict, n: int) -> tuple:
    """``(G, nu)`` of the shaft: one of them given (per station or in ``[shaft]``), the other None."""
    if "poisson_ratio" in shaft and "shear_modulus" in shaft:
        raise ctx.err("[shaft]", "give poisson_ratio or shear_modulus, not both")
    G = ctx.number(shaft, "shear_modulus", "modulus", "[shaft]", positive=True) if "shear_modulus" in shaft \
        else None
    nu = None
    if G is None:
        nu = ctx.number(shaft, "poisson_ratio", "dimensionless", "[shaft]", default=DEFAULT_POISSON_RATIO,
                        nonneg=False)
        if not -1 < nu < 0.5:
            raise ctx.err("[shaft], poisson_ratio", f"must be in (-1, 0.5), got {nu}")
    if per_station_G:
        if len(per_station_G) != n - 1 and len(per_station_G) != n:
            raise ctx.err("[[station]]", "shear_modulus must be given on every station or on none")
        vals = list(per_station_G.values())[:n - 1]
        if not _uniform(vals):
            raise ctx.err("[[station]], shear_modulus", "different shear moduli per station are not supported")
        G, nu = vals[0], None
    return G, nu


def _planes_and_speed(ctx: _Ctx, doc: dict) -> tuple[int, float]:
    """The bending planes (1 or 2) and the running speed [rad/s] of the top level."""
    planes = doc.get("planes", 2)
    if planes not in (1, 2) or isinstance(planes, bool):
        raise ctx.err("planes", f"must be 1 or 2, got {planes!r}")
    if "speed" in doc and "speed_rpm" in doc:
        raise ctx.err("top level", "give speed (rad/s) or speed_rpm, not both")
    speed = 0.0
    if "speed" in doc:
        speed = ctx.number(doc, "speed", "angular_speed", "top level", nonneg=False)
    elif "speed_rpm" in doc:
        speed = U.rpm_to_rad_s(ctx.number(doc, "speed_rpm", "dimensionless", "top level", nonneg=False))
    return planes, speed


def _disks(ctx: _Ctx, doc: dict, n: int) -> list:
    """The ``[[disk]]`` tables: rigid disks from mass and inertias or from their geometry."""
    extra = []
    for k, t in enumerate(_array_of_tables(ctx, doc, "disk"), start=1):
        where = f"[[disk]] #{k}"
        ctx.check_keys(t, _DISK, where)
        s = ctx.station(t, where, n)
        name = ctx.string(t, "name", where)
        if "mass" in t:
            for key in ("width", "outer_diameter", "inner_diameter", "density"):
                if key in t:
                    raise ctx.err(where, f"give mass/polar_inertia/transverse_inertia or the geometry, "
                                  f"not both ('{key}')")
            extra.append(DiskElement(s, ctx.number(t, "mass", "mass", where),
                                     ctx.number(t, "polar_inertia", "inertia", where, default=0.0),
                                     ctx.number(t, "transverse_inertia", "inertia", where, default=0.0),
                                     name=name or f"disk{s}_{k}"))
        else:
            if "polar_inertia" in t or "transverse_inertia" in t:
                raise ctx.err(where, "inertias without 'mass'")
            extra.append(DiskElement.from_geometry(
                s, ctx.number(t, "width", "length", where, positive=True),
                ctx.number(t, "outer_diameter", "length", where, positive=True),
                ctx.number(t, "inner_diameter", "length", where, default=0.0),
                ctx.number(t, "density", "density", where, positive=True), name=name or f"disk{s}_{k}"))
    return extra


def _bearings(ctx: _Ctx, doc: dict, n: int, planes: int = 2) -> list:
    """The ``[[bearing]]`` tables (cross-coupled stiffness ``kxy``, ``kyx``, either sign: two planes only)."""
    extra = []
    for k, t in enumerate(_array_of_tables(ctx, doc, "bearing"), start=1):
        where = f"[[bearing]] #{k}"
        ctx.check_keys(t, _BEARING, where, required=("station", "stiffness"))
        s = ctx.station(t, where, n)
        kw = {}
        if "stiffness_y" in t:
            kw["kyy"] = ctx.number(t, "stiffness_y", "stiffness", where)
        if "damping_y" in t:
            kw["cyy"] = ctx.number(t, "damping_y", "damping", where)
        for key in ("kxy", "kyx"):
            if key in t:
                kw[key] = ctx.number(t, key, "stiffness", where, nonneg=False)
                if planes != 2:
                    raise ctx.err(f"{where}, {key}", "cross-coupled stiffness needs both bending planes "
                                                     f"(planes = 2), the file has planes = {planes}")
        extra.append(BearingElement(s, ctx.number(t, "stiffness", "stiffness", where),
                                    ctx.number(t, "damping", "damping", where, default=0.0),
                                    name=ctx.string(t, "name", where) or f"bearing{s}", **kw))
    return extra


def _exciters(ctx: _Ctx, doc: dict, n: int, planes: int) -> list:
    """The ``[[exciter]]`` tables (magnetic exciters, current in)."""
    extra = []
    for k, t in enumerate(_array_of_tables(ctx, doc, "exciter"), start=1):
        where = f"[[exciter]] #{k}"
        ctx.check_keys(t, _EXCITER, where, required=("station", "force_per_ampere"))
        s = ctx.station(t, where, n)
        extra.append(ExciterElement(s, ctx.number(t, "force_per_ampere", "force_per_current", where),
                                    ctx.number(t, "negative_stiffness", "stiffness", where, default=0.0),
                                    direction=_direction(ctx, t, where, planes),
                                    port=ctx.string(t, "name", where), name=f"exciter{s}"))
    return extra


def _rotor_ports(ctx: _Ctx, doc: dict, n: int, planes: int) -> tuple[list, list]:
    """The ``[[force]]`` inputs and ``[[sensor]]`` outputs."""
    ins, outs = [], []
    for k, t in enumerate(_array_of_tables(ctx, doc, "force"), start=1):
        where = f"[[force]] #{k}"
        ctx.check_keys(t, _PORT_ROTOR, where, required=("station",))
        s = ctx.station(t, where, n)
        d = _direction(ctx, t, where, planes)
        ins.append(InputPort(ctx.string(t, "name", where) or f"F{s}" + ("y" if d == "v" else ""), s, d))
    for k, t in enumerate(_array_of_tables(ctx, doc, "sensor"), start=1):
        where = f"[[sensor]] #{k}"
        ctx.check_keys(t, _PORT_ROTOR, where, required=("station",))
        s = ctx.station(t, where, n)
        d = _direction(ctx, t, where, planes)
        outs.append(OutputPort(ctx.string(t, "name", where) or ("y" if d == "v" else "x") + str(s), s, d))
    return ins, outs


def _cracks(ctx: _Ctx, doc: dict, n: int, extra: list) -> list:
    """Append the ``[[crack]]`` elements to ``extra``; ``(index, table, where, station)`` of each
    ``breathing = "auto"`` crack, built as a Mayes crack for now (:func:`_auto_breathing`)."""
    auto = []
    for k, t in enumerate(_array_of_tables(ctx, doc, "crack"), start=1):
        where = f"[[crack]] #{k}"
        if not isinstance(t, dict):
            raise ctx.err(where, "expected a table")
        if "depth_ratio" not in t:
            raise ctx.err(where, "missing 'depth_ratio'")
        s = ctx.station(t, where, n - 1)
        t = _auto_keys(ctx, t, where)
        if t.get("breathing") == "auto":
            auto.append((len(extra), t, where, s))
        # an "auto" crack is checked as a Mayes crack now and built with its law below
        extra.append(_make_crack(ctx, {kk: ("mayes" if kk == "breathing" and vv == "auto" else vv)
                                       for kk, vv in t.items() if kk not in _AUTO_KEYS}, where, s))
    return auto


def _auto_breathing(ctx: _Ctx, auto: list, extra: list, build) -> dict:
    """Build each ``breathing = "auto"`` crack of ``extra`` with the law its slot width and the
    rotor's weight choose (``build`` assembles a rotor from elements); crack name -> choice."""
    choices = {}
    if auto:
        # the weight's moment at each "auto" crack, on the rotor without those cracks
        skip = {i for i, *_ in auto}
        plain = build([e for i, e in enumerate(extra) if i not in skip])
        from .crack import choose_breathing
        for i, t, where, s in auto:
            try:
                ch = choose_breathing(plain, s, float(t["depth_ratio"]), t["slot_width"],
                                      xi=float(t.get("xi", 0.0)), closing_law=t.get("closing_law", "mayes"),
                                      name=f"{ctx.source} {where}")
            except ModelError as exc:
                raise ctx.err(where, str(exc).replace(f"{ctx.source} {where}: ", "")) from None
            tt = {kk: vv for kk, vv in t.items() if kk not in _AUTO_KEYS}
            tt["breathing"] = ch.law
            extra[i] = _make_crack(ctx, tt, where, s)
            extra[i].breathing_choice = ch
            choices[extra[i].name] = ch
    return choices


def _direction(ctx, t, where, planes):
    d = ctx.string(t, "direction", where, default="x")
    table = {"x": "u", "y": "v"}
    if d not in table:
        raise ctx.err(f"{where}, direction", f"must be 'x' or 'y', got {d!r}")
    if d == "y" and planes == 1:
        raise ctx.err(f"{where}, direction", "'y' needs planes = 2")
    return table[d]


_AUTO_KEYS = ("slot_width", "closing_law")


def _auto_keys(ctx, t, where):
    """Check the keys of ``breathing = "auto"`` (slot_width, closing_law); the table unchanged."""
    b = t.get("breathing")
    if b == "auto":
        if "slot_width" not in t:
            raise ctx.err(where, "breathing = 'auto' needs slot_width [m] (the gap between the crack faces "
                          "at rest; 0 for a fatigue crack)")
        t = dict(t, slot_width=ctx.number(t, "slot_width", "length", where))
        law = t.get("closing_law", "mayes")
        if law not in ("mayes", "gasch"):
            raise ctx.err(f"{where}, closing_law", f"must be 'mayes' or 'gasch' (the law when the faces "
                          f"touch), got {law!r}")
    else:
        for key in _AUTO_KEYS:
            if key in t:
                raise ctx.err(f"{where}, {key}", "only with breathing = 'auto'")
    return t


def _make_crack(ctx, t, where, station):
    try:
        from .crack import Crack  # provided by mutext.rotor.crack
    except ImportError as exc:
        raise ctx.err(where, f"crack elements need mutext.rotor.crack, which cannot be imported ({exc})") \
            from None
    kw = {k: v for k, v in t.items() if k != "station"}
    if "name" not in kw:
        kw["name"] = f"crack{station}"
    try:
        return Crack(station=station, **kw)
    except TypeError as exc:
        raise ctx.err(where, f"bad crack entry: {exc}") from None
