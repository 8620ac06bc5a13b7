r"""Model files (TOML): rotors on bearings, and lumped mass-spring-damper chains.

A model file is read with :func:`load_model` and becomes a
:class:`~mutext.rotor.assembly.Rotor` or a
:class:`~mutext.rotor.assembly.Structure` (lumped chain).  Numbers are SI
unless the top-level key ``units = "inch-pound"`` says otherwise (then: in,
lb (mass), lb in^2, lb/in^3, psi, lbf/in, lbf s/in, lbf/A; see
:mod:`mutext.rotor.units`).  A station table file keeps its own fixed
inch-pound units (:mod:`mutext.rotor.table`) whatever ``units`` says.

Rotor files
-----------
.. code-block:: toml

    name = "thesis healthy rotor"
    units = "SI"                 # or "inch-pound"
    planes = 2                   # 2: both bending planes + gyroscopics; 1: x-z plane
    speed_rpm = 600              # or speed = 62.83 (rad/s); default 0

    [shaft]
    station_table = "rotor_healthy.txt"   # path relative to this file
    poisson_ratio = 0.3                   # or shear_modulus = ... (the table has neither)
    ports_from_flags = true               # table flags -> ports F<s>, x<s>, M<s>, psi<s>

    # ... or inline stations instead of station_table (length = element to the next station):
    # [[station]]
    # length = 0.25
    # outer_diameter = 0.05
    # inner_diameter = 0.0        # optional
    # youngs_modulus = 211e9
    # density = 7810
    # shear_modulus = 81.2e9      # optional; else [shaft] poisson_ratio / shear_modulus
    # added_mass = 0.0            # optional, also added_polar_inertia, added_transverse_inertia
    # force_input = false         # optional port flags: force_input, displacement_output,
    #                             #   moment_input, rotation_output

    [[disk]]                      # mass, polar_inertia, transverse_inertia ... or geometry:
    station = 3                   # width, outer_diameter, inner_diameter, density
    width = 0.07
    outer_diameter = 0.28
    inner_diameter = 0.05
    density = 7810

    [[bearing]]
    station = 2
    stiffness = 1.0e7             # N/m; stiffness_y for anisotropic bearings
    damping = 0.0                 # N s/m; damping_y

    [[exciter]]
    station = 12
    force_per_ampere = 40.0       # N/A
    negative_stiffness = 0.0      # N/m (magnetic actuator), optional
    name = "i12"                  # input name, optional; direction = "x" optional

    [[force]]                     # force input (N) named F<station>[y] unless name given
    station = 5

    [[sensor]]                    # displacement output (m) named x<station> / y<station>
    station = 13
    direction = "x"

    [damping]
    modal = 0.01                  # same ratio in every mode ... or alpha = ..., beta = ...
                                  # (proportional: see "Damping" below)

    [[crack]]                     # needs mutext.rotor.crack
    station = 15
    depth_ratio = 0.4
    perpendicular = true          # optional, default true: both bending compliances (c55, c44);
                                  # false: c55 only, the one-compliance (hinge) model
    breathing = "mayes"           # optional: the crack turns with the shaft; orientation = its angle
                                  # at t = 0 [rad].  "gaping" (also "open", "notch"): always open,
                                  # stiffness varying at 2x only (a slot whose faces never touch);
                                  # "mayes", "gasch": opens and closes under weight (1x, 2x, 3x ...);
                                  # "auto": chosen from slot_width [m] (gap between the faces at rest,
                                  # 0 for a fatigue crack) against the faces' movement under the
                                  # rotor's weight (mutext.rotor.crack.choose_breathing; closing_law =
                                  # "mayes" (default) or "gasch" when they touch).  The choice and why:
                                  # rotor.breathing_choices[name].  Time-invariant analyses use the
                                  # revolution average; the time-periodic rotor is mutext.rotor.periodic

Lumped chains
-------------
.. code-block:: toml

    name = "three-mass rig"
    [[mass]]
    name = "m1"
    mass = 2.8113
    [[spring]]
    name = "k1"
    stiffness = 842.3
    between = ["m1", "m2"]        # or ["m3", "ground"]
    [[damper]]
    name = "c1"
    damping = 5.2992
    between = ["m1", "ground"]
    [[force]]
    name = "f1"
    mass = "m1"
    [[sensor]]
    name = "x1"
    mass = "m1"
    [[impedance]]                 # a rational dynamic stiffness K(s) to ground at a mass (optional)
    name = "K_m2"
    mass = "m2"
    numerator = [0.5, 40.0, 900.0]    # coefficients of s^2, s, 1: K(s) in N/m
    denominator = [1.0, 20.0]         # coefficients of s, 1 (degree >= the numerator's)

``[[impedance]]`` applies the force :math:`-K(s)\,x` to its mass
(:class:`~mutext.rotor.lumped_elements.Impedance`): the frequency response
adds :math:`K(j\omega)` to the dynamic stiffness and the state space gains
its states.  It is how :mod:`mutext.diagnose` writes what model-based
identification found when that is not a mass, a damper and a spring.  It has
no tunable parameter; undamped modes and tuning refuse a model that holds one.
In an inch-pound file :math:`K` is in lbf/in (the numerator is converted).

Damping
-------
``[damping] modal = z`` gives every mode of the undamped structure the damping
ratio *z* (:class:`~mutext.rotor.assembly.ModalDamping`, recomputed from the
modes of the model as built, added elements included).

``[damping] alpha = a, beta = b`` is proportional damping
(:class:`~mutext.rotor.elements.StructuralDamping`): :math:`C \mathrel{+}=
\alpha M + \beta K_s`.  ``alpha`` [1/s] multiplies the whole mass matrix;
``beta`` [s] multiplies :math:`K_s`, the stiffness of the structure's own
members only -- the shaft elements and the cracks in them (rotors), the
springs between two masses (lumped chains).  The connections to ground --
``[[bearing]]``, ``[[exciter]]`` (its negative stiffness) and a ``[[spring]]``
with one end on ``"ground"`` -- carry only the damping they are given (a
bearing's ``damping``, a ``[[damper]]``): a grounded spring or bearing added
to the file, e.g. ``damping = 0.0`` by :mod:`mutext.diagnose`, leaves the
damping matrix unchanged.  (A structural spring to ground that should share
the material damping needs its own ``[[damper]]``, of value
:math:`\beta k`.)  A mode of a structure without such connections gets
:math:`\zeta = \alpha/(2\omega) + \beta\omega/2`; with them the
:math:`\beta` term is about :math:`\beta\omega/2` times the share of the
mode's strain energy stored in the members.

The parameter of a lumped element is called by the element's name (``"m1"``,
``"k1"``, ``"c1"``).  In rotors: ``"E"`` and ``"rho"`` (one each when all
shaft elements share the value, else ``"shaft<s>.E"``), ``"nu"`` or ``"G"``,
``"shaft<s>.L"``, ``".do"``, ``".di"``, ``"disk<s>.m"``, ``".Ip"``, ``".Id"``,
``"bearing<s>.k"``, ``".c"``, ``"exciter<s>.ki"``, ``".kx"``; proportional damping:
``"damping.alpha"``, ``"damping.beta"``.

Errors name the file, the table (``[[bearing]] #2``) and key, and the problem.
"""
from __future__ import annotations

import difflib
import math
import os
import tomllib
from typing import Any

from ..errors import ModelError
from . import units as U
from .assembly import ModalDamping, Rotor, Structure
from .elements import (BearingElement, Damper, DiskElement, ExciterElement, InputPort, OutputPort, Param,
                       PointMass, ShaftElement, Spring, StructuralDamping)
from .lumped_elements import Impedance
from .table import Station, StationTable, read_station_table

__all__ = ["load_model", "loads_model", "rotor_from_table", "DEFAULT_POISSON_RATIO"]

#: Poisson's ratio used when a station table is read without one (steel).
DEFAULT_POISSON_RATIO = 0.3

_TOP_ROTOR = {"name", "units", "planes", "speed", "speed_rpm", "shaft", "station", "disk", "bearing",
              "exciter", "force", "sensor", "damping", "crack", "description"}
_TOP_LUMPED = {"name", "units", "mass", "spring", "damper", "force", "sensor", "damping", "description",
               "impedance"}

# key -> quantity (None: not a number, handled separately)
_SHAFT = {"station_table": None, "poisson_ratio": "dimensionless", "shear_modulus": "modulus",
          "ports_from_flags": None}
_STATION = {"length": "length", "outer_diameter": "length", "inner_diameter": "length",
            "youngs_modulus": "modulus", "density": "density", "shear_modulus": "modulus",
            "added_mass": "mass", "added_polar_inertia": "inertia", "added_transverse_inertia": "inertia",
            "force_input": None, "displacement_output": None, "moment_input": None, "rotation_output": None}
_DISK = {"station": None, "name": None, "mass": "mass", "polar_inertia": "inertia",
         "transverse_inertia": "inertia", "width": "length", "outer_diameter": "length",
         "inner_diameter": "length", "density": "density"}
_BEARING = {"station": None, "name": None, "stiffness": "stiffness", "damping": "damping",
            "stiffness_y": "stiffness", "damping_y": "damping"}
_EXCITER = {"station": None, "name": None, "direction": None, "force_per_ampere": "force_per_current",
            "negative_stiffness": "stiffness"}
_PORT_ROTOR = {"station": None, "name": None, "direction": None}
_MASS = {"name": None, "mass": "mass"}
_SPRING = {"name": None, "between": None, "stiffness": "stiffness"}
_DAMPER = {"name": None, "between": None, "damping": "damping"}
_PORT_LUMPED = {"name": None, "mass": None}
_IMPEDANCE = {"name": None, "mass": None, "numerator": None, "denominator": None}
_DAMPING = {"modal": "dimensionless", "alpha": None, "beta": None}


class _Ctx:
    """Error context: file name and unit system."""

    def __init__(self, source: str, system: str):
        self.source = source
        self.system = system

    def err(self, where: str, msg: str) -> ModelError:
        return ModelError(f"{self.source}: {where}: {msg}")

    def check_keys(self, tbl: Any, allowed, where: str, required=()):
        if not isinstance(tbl, dict):
            raise self.err(where, f"expected a table, got {type(tbl).__name__}")
        for k in tbl:
            if k not in allowed:
                close = difflib.get_close_matches(k, list(allowed), n=1)
                hint = f" (did you mean '{close[0]}'?)" if close else ""
                raise self.err(where, f"unknown key '{k}'{hint}; allowed: {', '.join(sorted(allowed))}")
        for k in required:
            if k not in tbl:
                raise self.err(where, f"missing '{k}'")

    def number(self, tbl, key, quantity, where, *, default=None, positive=False, nonneg=True):
        if key not in tbl:
            if default is None:
                raise self.err(where, f"missing '{key}'")
            return default
        v = tbl[key]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise self.err(f"{where}, {key}", f"expected a finite number, got {v!r}")
        if positive and v <= 0:
            raise self.err(f"{where}, {key}", f"must be positive, got {v!r}")
        if nonneg and v < 0:
            raise self.err(f"{where}, {key}", f"must be non-negative, got {v!r}")
        return U.to_si(v, quantity, self.system)

    def string(self, tbl, key, where, default=None):
        v = tbl.get(key, default)
        if v is not None and not isinstance(v, str):
            raise self.err(f"{where}, {key}", f"expected a string, got {v!r}")
        return v

    def boolean(self, tbl, key, where, default=False):
        v = tbl.get(key, default)
        if not isinstance(v, bool):
            raise self.err(f"{where}, {key}", f"expected true or false, got {v!r}")
        return v

    def station(self, tbl, where, n_stations):
        if "station" not in tbl:
            raise self.err(where, "missing 'station'")
        s = tbl["station"]
        if isinstance(s, bool) or not isinstance(s, int):
            raise self.err(f"{where}, station", f"expected an integer station number, got {s!r}")
        if not 1 <= s <= n_stations:
            raise self.err(f"{where}, station", f"station {s} is outside 1..{n_stations}")
        return s


def _array_of_tables(ctx, doc, key):
    v = doc.get(key, [])
    if isinstance(v, dict):
        v = [v]
    if not isinstance(v, list) or not all(isinstance(t, dict) for t in v):
        raise ctx.err(f"[[{key}]]", "expected an array of tables ([[" + key + "]] sections)")
    return v


# ---------------------------------------------------------------------------
# station table -> rotor elements
# ---------------------------------------------------------------------------

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
    n = len(table)

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
    ports = ctx.boolean(shaft, "ports_from_flags", "[shaft]", default=True)

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

    extra, ins, outs = [], [], []
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
    for k, t in enumerate(_array_of_tables(ctx, doc, "bearing"), start=1):
        where = f"[[bearing]] #{k}"
        ctx.check_keys(t, _BEARING, where, required=("station", "stiffness"))
        s = ctx.station(t, where, n)
        kw = {}
        if "stiffness_y" in t:
            kw["kyy"] = ctx.number(t, "stiffness_y", "stiffness", where)
        if "damping_y" in t:
            kw["cyy"] = ctx.number(t, "damping_y", "damping", where)
        extra.append(BearingElement(s, ctx.number(t, "stiffness", "stiffness", where),
                                    ctx.number(t, "damping", "damping", where, default=0.0),
                                    name=ctx.string(t, "name", where) or f"bearing{s}", **kw))
    for k, t in enumerate(_array_of_tables(ctx, doc, "exciter"), start=1):
        where = f"[[exciter]] #{k}"
        ctx.check_keys(t, _EXCITER, where, required=("station", "force_per_ampere"))
        s = ctx.station(t, where, n)
        extra.append(ExciterElement(s, ctx.number(t, "force_per_ampere", "force_per_current", where),
                                    ctx.number(t, "negative_stiffness", "stiffness", where, default=0.0),
                                    direction=_direction(ctx, t, where, planes),
                                    port=ctx.string(t, "name", where), name=f"exciter{s}"))
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
    rotor = build(extra)
    rotor.breathing_choices = choices
    rotor.table = table
    rotor.source = ctx.source
    rotor.units = ctx.system
    return rotor


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


def _damping(ctx, d):
    if d is None:
        return None
    ctx.check_keys(d, _DAMPING, "[damping]")
    if "modal" in d and ("alpha" in d or "beta" in d):
        raise ctx.err("[damping]", "give modal or alpha/beta (proportional), not both")
    if "modal" in d:
        z = ctx.number(d, "modal", "dimensionless", "[damping]")
        if not z < 1:
            raise ctx.err("[damping], modal", f"a damping ratio must be below 1, got {z}")
        return ModalDamping(z)
    if "alpha" in d or "beta" in d:
        a = ctx.number(d, "alpha", "dimensionless", "[damping]", default=0.0)
        b = ctx.number(d, "beta", "dimensionless", "[damping]", default=0.0)
        return StructuralDamping(a, b)
    raise ctx.err("[damping]", "expected 'modal' or 'alpha'/'beta'")


# ---------------------------------------------------------------------------
# lumped chains
# ---------------------------------------------------------------------------

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


# ---------------------------------------------------------------------------
# entry points
# ---------------------------------------------------------------------------

def loads_model(text: str, *, source: str = "<string>", base_dir: str = ".", station_table=None):
    """Build a model from TOML text (see the module docstring).

    Parameters
    ----------
    text : str
        The model file's contents (TOML): a rotor (``[shaft]`` or
        ``[[station]]`` tables) or a lumped chain (``[[mass]]`` tables).
    source : str, optional
        Name of the text in error messages (a file name).
    base_dir : str, optional
        Directory against which a station-table path in the text is resolved.
    station_table : str, path-like or StationTable, optional
        Use this station table instead of the one the text names.

    Returns
    -------
    Rotor or Structure

    Raises
    ------
    ModelError
        Invalid TOML, or a table or field that breaks the format's rules
        (named with its table and key).

    Examples
    --------
    >>> from mutext.rotor import loads_model
    >>> chain = loads_model('''
    ... [[mass]]
    ... name = "m1"
    ... mass = 1.0
    ... [[spring]]
    ... name = "k1"
    ... between = ["m1", "ground"]
    ... stiffness = 100.0
    ... ''')
    >>> chain.natural_frequencies().round(4)            # sqrt(100 / 1) / 2 pi Hz
    array([1.5915])
    """
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"{source}: not valid TOML: {exc}") from None
    system = doc.get("units", "SI")
    if system not in U.SYSTEMS:
        raise ModelError(f"{source}: units: expected one of {sorted(U.SYSTEMS)}, got {system!r}")
    ctx = _Ctx(source, system)
    rotor_keys = {"shaft", "station"} & set(doc)
    lumped_keys = {"mass", "spring", "damper"} & set(doc)
    if rotor_keys and lumped_keys:
        raise ctx.err("top level", f"mixes rotor tables ({', '.join(sorted(rotor_keys))}) and lumped tables "
                      f"({', '.join(sorted(lumped_keys))})")
    if lumped_keys:
        if station_table is not None:
            raise ctx.err("top level", "station_table given for a lumped model")
        return _load_lumped(ctx, doc)
    if rotor_keys or station_table is not None:
        return _load_rotor(ctx, doc, base_dir, station_table)
    raise ctx.err("top level", "neither a rotor ([shaft] or [[station]]) nor a lumped chain ([[mass]])")


def load_model(path: str | os.PathLike, *, station_table: str | os.PathLike | None = None):
    """Read a model file (TOML) and build a :class:`Rotor` or lumped :class:`Structure`.

    Parameters
    ----------
    path : path-like
        The model file.
    station_table : path-like, optional
        Use this station table instead of the one the file names (e.g. the
        cracked rotor's table with the healthy rotor's bearings and exciter).

    Examples
    --------
    The three-mass rig shipped with the package (a lumped chain):

    >>> from mutext.rotor import data_path, load_model
    >>> rig = load_model(data_path("three_mass.toml"))
    >>> rig.dof_names, rig.input_names, rig.output_names
    (['m1', 'm2', 'm3'], ['f1', 'f3'], ['x1', 'x3'])
    >>> rig.natural_frequencies().round(3)              # Hz
    array([0.952, 3.12 , 4.919])
    """
    path = os.fspath(path)
    try:
        with open(path, "rb") as fh:
            raw = fh.read()
    except OSError as exc:
        raise ModelError(f"cannot read model file '{path}': {exc.strerror}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise ModelError(f"{path}: not UTF-8 text") from None
    return loads_model(text, source=path, base_dir=os.path.dirname(os.path.abspath(path)),
                       station_table=station_table)
