r"""Station tables in the format of the thesis appendix.

One row per station, left to right, 12 whitespace-separated numbers; ``#``
starts a comment (whole line or end of line); blank lines are ignored.

=====  ===========================  ===================  ====================
col    field                        unit in the file     SI (after reading)
=====  ===========================  ===================  ====================
1      added weight                 lb (pound-mass)      kg
2      length of the element that   in                   m
       starts at this station
3      outer diameter               in                   m
4      inner diameter               in                   m
5      added polar inertia          lb in^2              kg m^2
6      added transverse inertia     lb in^2              kg m^2
7      Young's modulus              Mpsi (10^6 lbf/in^2) Pa
8      mass density                 lb/in^3              kg/m^3
9      translational input flag     0/1
10     translational output flag    0/1
11     rotational input flag        0/1
12     rotational output flag       0/1
=====  ===========================  ===================  ====================

The shaft element between stations *i* and *i+1* has the length, diameters,
modulus and density of row *i*; the last station has length 0 (its diameters,
modulus and density are not used).  "lb" is read as pound-mass; see
:mod:`mutext.rotor.units` for why this is the only sensible reading and why it
equals the "weight in lbf divided by g0" convention.

The thesis table gives no units; the ones above are the interpretation under
which the numbers describe the rig (26 in long, 0.625 in shaft, steel).
Numbers in the table are converted to SI in :func:`parse_station_table` and
nowhere else.

Station numbers are 1-based, as in the thesis (station 12 is the exciter).

References
----------
R. J. Madden, *Identification of unmodeled dynamics in rotor systems using
mu-synthesis approach*, M.S. thesis, Cleveland State University, sec. 4.3
and appendix.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError
from . import units

__all__ = ["COLUMNS", "Station", "StationTable", "parse_station_table", "read_station_table"]

#: (field name, quantity, unit label in the file, description); column i+1 is COLUMNS[i]
COLUMNS = (
    ("added_mass", "mass", "lb", "added weight"),
    ("length", "length", "in", "length"),
    ("outer_diameter", "length", "in", "outer diameter"),
    ("inner_diameter", "length", "in", "inner diameter"),
    ("added_polar_inertia", "inertia", "lb in^2", "added polar moment of inertia"),
    ("added_transverse_inertia", "inertia", "lb in^2", "added transverse moment of inertia"),
    ("youngs_modulus", "modulus_mpsi", "Mpsi", "Young's modulus"),
    ("density", "density", "lb/in^3", "mass density"),
    ("translational_input", "flag", "0/1", "translational input flag"),
    ("translational_output", "flag", "0/1", "translational output flag"),
    ("rotational_input", "flag", "0/1", "rotational input flag"),
    ("rotational_output", "flag", "0/1", "rotational output flag"),
)
NCOL = len(COLUMNS)
FLAGS = ("translational_input", "translational_output", "rotational_input", "rotational_output")


@dataclass(frozen=True)
class Station:
    """One station (node) of a rotor, in SI units.

    Attributes
    ----------
    number : int
        1-based station number.
    added_mass : float
        Lumped mass at the station [kg].
    length : float
        Length of the shaft element from this station to the next [m]; 0 for the last station.
    outer_diameter, inner_diameter : float
        Diameters of that shaft element [m].
    added_polar_inertia, added_transverse_inertia : float
        Lumped polar and transverse (diametral) inertia at the station [kg m^2].
    youngs_modulus : float
        Young's modulus of the shaft element [Pa].
    density : float
        Mass density of the shaft element [kg/m^3].
    translational_input, translational_output, rotational_input, rotational_output : bool
        Port flags: a force input, a displacement output, a moment input, a rotation output.
    source : str
        ``file:line`` the row came from (for error messages).
    """
    number: int
    added_mass: float
    length: float
    outer_diameter: float
    inner_diameter: float
    added_polar_inertia: float
    added_transverse_inertia: float
    youngs_modulus: float
    density: float
    translational_input: bool = False
    translational_output: bool = False
    rotational_input: bool = False
    rotational_output: bool = False
    source: str = ""


@dataclass
class StationTable:
    """An ordered list of :class:`Station` (SI units) with its origin.

    Attributes
    ----------
    stations : list of Station
        The stations, in order.
    source : str
        Where the table was read from (file name), for messages.
    comments : list of str
        Comment lines of the file.
    """
    stations: list[Station]
    source: str = "<table>"
    comments: list[str] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.stations)

    def __iter__(self):
        return iter(self.stations)

    def __getitem__(self, number: int) -> Station:
        """Station by its 1-based number."""
        if not 1 <= number <= len(self.stations):
            raise ModelError(f"{self.source}: station {number} is outside 1..{len(self.stations)}")
        return self.stations[number - 1]

    @property
    def positions(self) -> np.ndarray:
        """Axial position of each station from the left end [m]."""
        return np.concatenate([[0.0], np.cumsum([s.length for s in self.stations[:-1]])])

    @property
    def total_length(self) -> float:
        """Overall length [m]."""
        return float(sum(s.length for s in self.stations))

    def flagged(self, flag: str) -> list[int]:
        """Station numbers whose ``flag`` (one of :data:`FLAGS`) is set.

        Parameters
        ----------
        flag : str
            One of :data:`FLAGS`, e.g. ``"translational_output"``.
        """
        if flag not in FLAGS:
            raise ModelError(f"unknown flag '{flag}'; expected one of {FLAGS}")
        return [s.number for s in self.stations if getattr(s, flag)]


def _convert(value: float, quantity: str) -> float:
    if quantity == "modulus_mpsi":
        return value * units.MPSI
    if quantity == "flag":
        return value
    return units.to_si(value, quantity, "inch-pound")


def parse_station_table(text: str, source: str = "<string>") -> StationTable:
    """Parse a station table (thesis appendix format, inch-pound units) into SI.

    Parameters
    ----------
    text : str
        Contents of the table.
    source : str
        Name used in error messages (the file name).

    Returns
    -------
    StationTable

    Raises
    ------
    ModelError
        Naming ``source``, the line and the column (number and field) of the
        first bad entry: wrong column count, a non-number, a negative length,
        diameter, mass or inertia, a non-positive modulus or density, an inner
        diameter not smaller than the outer one, a flag other than 0/1, a zero
        length before the last station, a nonzero length on the last station,
        or fewer than two stations.
    """
    rows = []          # (line number, [floats])
    comments = []
    for lineno, raw in enumerate(text.splitlines(), start=1):
        body, hash_, comment = raw.partition("#")
        if hash_:
            comments.append(comment.strip())
        tokens = body.split()
        if not tokens:
            continue
        where = f"{source}, line {lineno}"
        if len(tokens) != NCOL:
            raise ModelError(f"{where}: expected {NCOL} columns (added weight, length, outer diameter, "
                             f"inner diameter, polar inertia, transverse inertia, modulus, density and "
                             f"4 port flags), found {len(tokens)}")
        vals = []
        for col, (tok, (name, _q, unit, _desc)) in enumerate(zip(tokens, COLUMNS), start=1):
            try:
                v = float(tok)
            except ValueError:
                raise ModelError(f"{where}, column {col} ({name} [{unit}]): '{tok}' is not a number") from None
            if not math.isfinite(v):
                raise ModelError(f"{where}, column {col} ({name} [{unit}]): '{tok}' is not finite")
            vals.append(v)
        rows.append((lineno, vals))
    if len(rows) < 2:
        raise ModelError(f"{source}: a station table needs at least 2 stations (one shaft element), "
                         f"found {len(rows)}")

    def bad(lineno, col, msg):
        name, _q, unit, _d = COLUMNS[col - 1]
        return ModelError(f"{source}, line {lineno}, column {col} ({name} [{unit}]): {msg}")

    stations = []
    for k, (lineno, v) in enumerate(rows):
        last = k == len(rows) - 1
        number = k + 1
        for col in (1, 2, 3, 4, 5, 6):
            if v[col - 1] < 0:
                raise bad(lineno, col, f"must be non-negative, got {v[col - 1]:g} (station {number})")
        for col in (7, 8):
            if v[col - 1] <= 0:
                raise bad(lineno, col, f"must be positive, got {v[col - 1]:g} (station {number})")
        for col in range(9, 13):
            if v[col - 1] not in (0.0, 1.0):
                raise bad(lineno, col, f"a flag must be 0 or 1, got {v[col - 1]:g} (station {number})")
        if last and v[1] != 0:
            raise bad(lineno, 2, f"the last station (station {number}) must have length 0 "
                      f"(a length is that of the element to the next station), got {v[1]:g}")
        if not last:
            if v[1] == 0:
                raise bad(lineno, 2, f"station {number} has a zero-length element; only the last station "
                          "has length 0 (merge the lumped parts into one station)")
            if v[2] == 0:
                raise bad(lineno, 3, f"the element starting at station {number} has zero outer diameter")
        if v[3] >= v[2] and (v[2] > 0 or v[3] > 0):
            raise bad(lineno, 4, f"inner diameter {v[3]:g} in must be smaller than the outer diameter "
                      f"{v[2]:g} in (station {number})")
        si = [_convert(x, q) for x, (_n, q, _u, _d) in zip(v, COLUMNS)]
        kw = {name: val for (name, *_), val in zip(COLUMNS, si)}
        for f in FLAGS:
            kw[f] = bool(kw[f])
        stations.append(Station(number=number, source=f"{source}:{lineno}", **kw))
    return StationTable(stations, source, comments)


def read_station_table(path: str | os.PathLike) -> StationTable:
    """Read a station table file (see :func:`parse_station_table`).

    Parameters
    ----------
    path : str or path-like
        The file (UTF-8 text).
    """
    try:
        path = os.fspath(path)
    except TypeError:
        raise ModelError(f"station table path must be a str or path-like, got {path!r}") from None
    try:
        with open(path, "rb") as fh:
            raw = fh.read()
    except OSError as exc:
        raise ModelError(f"cannot read station table '{path}': {exc.strerror or exc}") from None
    if b"\x00" in raw:
        raise ModelError(f"{path}: binary file (it contains NUL bytes, e.g. UTF-16 text); a station table is "
                         "UTF-8 (or ASCII) text")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        raise ModelError(f"{path}, line {line}: not UTF-8 text (byte 0x{raw[exc.start]:02x}); save the station "
                         "table as UTF-8 or ASCII") from None
    return parse_station_table(text, source=path)
