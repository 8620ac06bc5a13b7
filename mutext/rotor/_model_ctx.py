"""The model-file reader's shared pieces: the allowed keys of every table, the error context
(:class:`_Ctx`: file name, unit system, checked numbers, strings and stations) and the
``[damping]`` table, read the same for rotors and lumped chains (:mod:`mutext.rotor.model`).
"""
from __future__ import annotations

import difflib
import math
from typing import Any

from ..errors import ModelError
from . import units as U
from .assembly import ModalDamping
from .elements import StructuralDamping

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
            "stiffness_y": "stiffness", "damping_y": "damping", "kxy": "stiffness", "kyx": "stiffness"}
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
