"""The FRF file format (module docstring of :mod:`mutext.rig`): its header keys, the quantities and units a
file may hold, and how a field is read (an error names the file, the line and the field)."""
from __future__ import annotations

import math

from ..response import FRFFileError
from ..uff import units_hint

#: CSV header line that separates the ``#`` header from the data.
CSV_HEADER = "freq_hz,re,im"

_REQUIRED = ("input_station", "input_quantity", "input_unit",
             "output_station", "output_quantity", "output_unit")
_OPTIONAL = ("speed_hz", "input_direction", "output_direction", "input_name", "output_name")
_RESERVED = _REQUIRED + _OPTIONAL
#: output quantities of a file -> units it may be given in (examples; any label of :func:`mutext.uff.parse_units`)
_OUTPUT_QUANTITIES = {"displacement": "m, mm, um (µm), cm, in, mil, ft",
                      "velocity": "m/s, mm/s, in/s",
                      "acceleration": "m/s^2 (m/s², m/s2), mm/s^2, g, in/s^2"}
_INPUT_UNIT_NAMES = {"force": "N, kN, lbf, lb", "current": "A, mA"}
_SI_MOTION = {"displacement": "m", "velocity": "m/s", "acceleration": "m/s^2"}
#: metadata set by the readers about the file read (not written back: the file written holds SI values)
_PROVENANCE = ("file_output_unit", "file_input_unit", "conversion")


def _parse_float(text: str, path, line: int, fld: str, allow_nonfinite: bool = False) -> float:
    try:
        v = float(text)
    except ValueError:
        raise FRFFileError(path, line, fld, f"{text.strip()!r} is not a number") from None
    if not allow_nonfinite and not math.isfinite(v):
        raise FRFFileError(path, line, fld, f"value is {text.strip()} (NaN or infinite values "
                                            f"are not allowed)")
    return v


def _parse_int(text: str, path, line: int, fld: str) -> int:
    try:
        return int(text.strip())
    except ValueError:
        raise FRFFileError(path, line, fld, f"{text.strip()!r} is not an integer") from None


def _units_error(path, ln, key, raw, what, why, allowed, example):
    return FRFFileError(path, ln, key, f"unknown unit {raw!r} for a {what} ({why}); allowed: {allowed}; "
                                       f"{units_hint(raw, example)}")
