r"""Reading the text of an FRF file (format in the :mod:`mutext.rig` docstring): the ``# key: value`` header,
the channel it describes (stations, quantities, units), the ``freq_hz,re,im`` rows, and the values converted
to displacement per force or current in SI (velocity divided by :math:`j\omega`, acceleration by
:math:`-\omega^2`)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..response import DIRECTIONS, FRF, INPUT_UNITS, FRFFileError
from ..uff import Units, dropped_note, motion_units, reference_units, relabel
from ._format import (_INPUT_UNIT_NAMES, _OUTPUT_QUANTITIES, _REQUIRED, _RESERVED, _SI_MOTION, CSV_HEADER,
                      _parse_float, _parse_int, _units_error)


@dataclass(frozen=True)
class _Channel:
    """The channel a file's header describes: stations, quantities, the units labels as written and read."""
    in_station: int
    out_station: int
    in_q: str
    in_u: str
    in_units: Units
    out_q: str
    out_u: str
    out_units: Units


def _read_csv(path, text: str, units: dict) -> FRF:
    """The FRF held by the text of the file ``path``; ``units``: {label in the file: label to read}."""
    lines = text.splitlines()
    header, i = _header(path, lines)
    # --- CSV header
    if i >= len(lines):
        raise FRFFileError(path, None, None, f"missing CSV header line {CSV_HEADER!r} "
                                             f"after the '#' header (file ends at line {len(lines)})")
    csv_line = i + 1
    cols = [c.strip().lower() for c in lines[i].split(",")]
    if cols != CSV_HEADER.split(","):
        raise FRFFileError(path, csv_line, None, f"expected the CSV header line {CSV_HEADER!r}, "
                                                 f"got {lines[i].strip()!r}")
    ch = _channel(path, header, units)
    speed, dirs, port_names = _options(path, header)
    f_hz, G, dropped = _rows(path, lines, i + 1, csv_line)
    G, meta = _to_si(f_hz, G, ch, header, units, dropped)
    return FRF(freq_hz=f_hz, response=G, input_station=ch.in_station, output_station=ch.out_station,
               input_quantity=ch.in_q, output_quantity="displacement", speed_hz=speed, metadata=meta, source=path,
               **dirs, **port_names)


def _header(path, lines) -> tuple[dict[str, tuple[str, int]], int]:
    """The ``# key: value`` lines at the top of ``lines`` as {key: (value, line number)}, and the index of the
    first line after them (blank lines skipped)."""
    header: dict[str, tuple[str, int]] = {}
    i = 0
    while i < len(lines):
        raw = lines[i].strip()
        if raw == "":
            i += 1
            continue
        if not raw.startswith("#"):
            break
        body = raw[1:].strip()
        key, sep, value = body.partition(":")
        key, value = key.strip(), value.strip()
        if not sep or not key:
            raise FRFFileError(path, i + 1, None, f"header line {raw!r} is not of the form "
                                                  f"'# key: value'")
        if key in header:
            raise FRFFileError(path, i + 1, key, f"key repeated (first given on line "
                                                 f"{header[key][1]})")
        header[key] = (value, i + 1)
        i += 1
    return header, i


def _one_of(path, key, entry, allowed, what: str) -> str:
    """The value of a header ``entry`` ``(value, line)`` that must be one of ``allowed``, or an
    :class:`FRFFileError` naming the ``key``, the line and the ``allowed`` values."""
    value, ln = entry
    if value not in allowed:
        raise FRFFileError(path, ln, key, f"unknown {what} {value!r}; allowed: {', '.join(allowed)}")
    return value


def _channel(path, header, units) -> _Channel:
    """The required keys of the header read: the stations, the quantities and their units (read as
    ``units`` says), which must agree."""
    for key in _REQUIRED:
        if key not in header:
            raise FRFFileError(path, None, key, f"missing required header key '{key}' "
                                                f"(required: {', '.join(_REQUIRED)})")
    in_station = _parse_int(header["input_station"][0], path, header["input_station"][1],
                            "input_station")
    out_station = _parse_int(header["output_station"][0], path, header["output_station"][1],
                             "output_station")
    in_q = _one_of(path, "input_quantity", header["input_quantity"], INPUT_UNITS, "quantity")
    in_u, ln = header["input_unit"]
    try:
        in_units = reference_units(relabel(in_u, units))
        if ("force" if in_units.dims[2] else "current") != in_q:
            raise ValueError(f"it is a {'force' if in_units.dims[2] else 'current'}")
    except ValueError as exc:
        raise _units_error(path, ln, "input_unit", in_u, f"{in_q} input", exc, _INPUT_UNIT_NAMES[in_q],
                           "N" if in_q == "force" else "A") from None
    out_q = _one_of(path, "output_quantity", header["output_quantity"], _OUTPUT_QUANTITIES, "quantity")
    out_u, ln = header["output_unit"]
    try:
        out_units = motion_units(relabel(out_u, units))
        if out_units.quantity != out_q:
            raise ValueError(f"it is a {out_units.quantity}")
        if out_units.reference is not None and (
                out_units.reference != in_q
                or not math.isclose(out_units.reference_factor * in_units.factor, 1.0, rel_tol=1e-9)):
            raise ValueError(f"per {out_units.reference} in other units than the input_unit {in_u!r}")
    except ValueError as exc:
        raise _units_error(path, ln, "output_unit", out_u, f"{out_q} output", exc, _OUTPUT_QUANTITIES[out_q],
                           _OUTPUT_QUANTITIES[out_q].split(",")[0]) from None
    return _Channel(in_station, out_station, in_q, in_u, in_units, out_q, out_u, out_units)


def _options(path, header) -> tuple[float | None, dict, dict]:
    """The optional keys of the header: the running speed, the directions and the port names."""
    speed = None
    if "speed_hz" in header:
        speed = _parse_float(header["speed_hz"][0], path, header["speed_hz"][1], "speed_hz")
    dirs = {}
    for key in ("input_direction", "output_direction"):
        dirs[key] = _one_of(path, key, header.get(key, ("x", None)), DIRECTIONS, "direction")
    port_names = {key: header[key][0] for key in ("input_name", "output_name") if key in header}
    return speed, dirs, port_names


def _rows(path, lines, start, csv_line) -> tuple[np.ndarray, np.ndarray, list]:
    """The ``freq_hz,re,im`` rows from ``lines[start]`` on: the frequencies [Hz] (strictly increasing, above
    0 Hz), the values, and the rows at or below 0 Hz dropped at the start as ``(frequency, line)``."""
    freqs, vals, dropped = [], [], []
    names = CSV_HEADER.split(",")
    for j in range(start, len(lines)):
        raw = lines[j].strip()
        if raw == "":
            continue
        if raw.startswith("#"):
            raise FRFFileError(path, j + 1, None, "header line after the CSV header "
                                                  "(all '# key: value' lines must come first)")
        parts = raw.split(",")
        if len(parts) != 3:
            raise FRFFileError(path, j + 1, None, f"expected 3 comma-separated values "
                                                  f"({CSV_HEADER}), got {len(parts)}")
        f = _parse_float(parts[0], path, j + 1, "freq_hz")
        if f <= 0 and not freqs:
            # an analyzer's 0 Hz line (or lines below it) at the start: dropped, with a note
            if dropped and f <= dropped[-1][0]:
                raise FRFFileError(path, j + 1, "freq_hz", f"frequency {f} Hz is not greater than the previous one "
                                                           f"({dropped[-1][0]} Hz on line {dropped[-1][1]})")
            for p, n in zip(parts[1:], names[1:]):
                _parse_float(p, path, j + 1, n, allow_nonfinite=True)
            dropped.append((f, j + 1))
            continue
        re_, im_ = (_parse_float(p, path, j + 1, n) for p, n in zip(parts[1:], names[1:]))
        if f <= 0:
            raise FRFFileError(path, j + 1, "freq_hz", f"frequency {f} Hz is not positive (only rows at the start "
                                                       f"may be at or below 0 Hz; they are dropped)")
        if freqs and f <= freqs[-1][0]:
            raise FRFFileError(path, j + 1, "freq_hz",
                               f"frequency {f} Hz is not greater than the previous one "
                               f"({freqs[-1][0]} Hz on line {freqs[-1][1]}); frequencies "
                               f"must be strictly increasing")
        freqs.append((f, j + 1))
        vals.append(complex(re_, im_))
    if not freqs:
        if dropped:
            raise FRFFileError(path, dropped[0][1], "freq_hz",
                               f"frequency {dropped[0][0]} Hz is not positive, and no row above 0 Hz follows; an "
                               f"FRF needs frequencies above 0 Hz")
        raise FRFFileError(path, csv_line, None, "no data rows after the CSV header")
    return np.array([f for f, _ in freqs]), np.array(vals), dropped


def _to_si(f_hz, G, ch: _Channel, header, units, dropped) -> tuple[np.ndarray, dict]:
    """The values ``G`` as displacement per force or current in SI, and the FRF's metadata: the header's other
    keys, the units as written, the conversion made and a note on the rows dropped."""
    in_q, in_u, in_units, out_q, out_u, out_units = ch.in_q, ch.in_u, ch.in_units, ch.out_q, ch.out_u, ch.out_units
    factor = out_units.factor if out_units.reference is not None else out_units.factor / in_units.factor
    defs = tuple(dict.fromkeys(out_units.definitions + in_units.definitions))
    in_si = "N" if in_q == "force" else "A"
    steps = []
    G = G * factor
    if factor != 1.0:
        steps.append(f"scaled by {factor:.12g} to {_SI_MOTION[out_q]}/{in_si}"
                     + (f" ({', '.join(defs)})" if defs else ""))
    if out_q == "velocity":
        G = G / (1j * 2 * np.pi * f_hz)
        steps.append("divided by j*omega")
    elif out_q == "acceleration":
        G = G / (-(2 * np.pi * f_hz) ** 2)
        steps.append("divided by -omega^2")
    meta = {k: v for k, (v, _) in header.items() if k not in _RESERVED}
    meta["file_output_unit"] = out_u
    meta["file_input_unit"] = in_u
    if steps:
        read_as = "" if relabel(out_u, units) == out_u and relabel(in_u, units) == in_u else \
            f", read as {relabel(out_u, units)} per {relabel(in_u, units)}"
        conv = (f"{out_q} per {in_q} in the file ({out_u} per {in_u}{read_as}) -> displacement per {in_q} "
                f"m/{in_si}: {', '.join(steps)}" + ("; omega = 2*pi*f [rad/s]" if out_q != "displacement" else ""))
        meta["conversion"] = f"{meta['conversion']}; then {conv}" if "conversion" in meta else conv
    if dropped:
        lns = f"line {dropped[0][1]}" if len(dropped) == 1 else f"lines {dropped[0][1]}-{dropped[-1][1]}"
        notes = [dropped_note([f for f, _ in dropped], lns)]
        meta["notes"] = ([meta["notes"]] if isinstance(meta.get("notes"), str) else []) + notes
    return G, meta
