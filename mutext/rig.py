r"""Frequency-response files and a virtual test rig.

Measured frequency response functions (FRFs) of the rotor rig are exchanged
as small text files, one input-output channel per file.

File format
-----------
::

    # input_station: 12
    # input_quantity: current
    # input_unit: A
    # output_station: 13
    # output_quantity: displacement
    # output_unit: um
    # speed_hz: 10
    # rig: cracked rotor, ball bearings
    freq_hz,re,im
    20.0,1.25e+01,-3.1e-01
    20.5,1.27e+01,-3.3e-01
    ...

* Header lines ``# key: value`` come first.  Required keys:
  ``input_station`` (int), ``input_quantity`` (``force`` or ``current``),
  ``input_unit`` (``N``, ``kN``, ``lbf``, ``lb`` for a force, ``A``, ``mA``
  for a current), ``output_station`` (int), ``output_quantity``
  (``displacement``, ``velocity`` or ``acceleration``), ``output_unit``
  (``m``, ``mm``, ``um``, ``in`` ...; ``m/s``, ``mm/s``, ``in/s`` ...;
  ``m/s^2``, ``m/s²``, ``g`` ... -- any label of
  :func:`mutext.uff.parse_units` of that quantity, which may also hold the
  whole ratio, e.g. ``(1/N)*(m/s²)``, if it agrees with ``input_unit``).
  Optional: ``speed_hz`` (float, running speed), ``input_direction`` and
  ``output_direction`` (``x`` or ``y``, the plane of a rotor; default ``x``),
  ``input_name`` and ``output_name`` (the model's port names).  Any other ``# key: value`` is kept
  as metadata (strings).  A combination-frequency response (a time-periodic
  rotor's response at :math:`f + kF` to excitation at :math:`f`, written by
  :func:`measure_rotor` with ``combination=``) says so with ``order: k``
  (integer, not 0) and ``response_frequency: f_exc + k * speed_hz``; its rows
  are on the excitation frequency and it needs ``speed_hz``.  Keys are case-sensitive and may appear once.
* Then the CSV header line ``freq_hz,re,im`` and one row per frequency:
  frequency in Hz (strictly increasing) and the real and imaginary parts of
  the response in ``output_unit`` per ``input_unit`` (e.g. um/A).  Blank
  lines are ignored.  Rows at or below 0 Hz at the start (an analyzer's 0 Hz
  line) are dropped with a note; a file with no row above 0 Hz is an error.
* UTF-8 text; a file that is not UTF-8 (``µm`` or ``m/s²`` written in
  Latin-1) is read as Latin-1, with a note.

:func:`read_frf` converts the response to displacement per force or current
in SI (m/N or m/A): units scaled, velocity divided by :math:`j\omega`,
acceleration by :math:`-\omega^2` (:math:`\omega = 2\pi f`).  Every format
error raises :class:`FRFFileError` naming the file, the line and the field; an
unknown unit also says what to change (edit the label, or pass
``units={label: label to read}``).

What the readers tell about a file read, in :attr:`FRF.metadata`:

* ``metadata["notes"]``: a list of str, present only when there is
  something to note (lines at or below 0 Hz dropped, text read as Latin-1).
  ``mutext frf convert`` and ``mutext frf resonances`` print them.
* ``metadata["conversion"]``: a str, present when the values were changed:
  what the file held and in what units, what it became, and each step (the
  scale factor with the definitions of the units it comes from, e.g.
  ``g = 9.80665 m/s^2``, ``in = 0.0254 m``, ``lbf = 4.4482216152605 N``;
  the division by :math:`j\omega` or :math:`-\omega^2`).  A Universal File
  also states it, changed or not, in ``metadata["uff_conversion"]``.
* ``metadata["file_output_unit"]``, ``metadata["file_input_unit"]``: the
  units labels as written.

:func:`write_frf` writes none of these back (the file it writes holds SI
values read as they stand).

Universal File Format data set 58 (``.uff``/``.unv``, the export of modal-test
software) is read too: :func:`read_frf` and :func:`read_frfs` hand such a file
to :func:`mutext.uff.read_uff58`, which converts velocity or acceleration per
force to displacement per force in SI; :func:`mutext.uff.write_uff58` writes it.

The virtual rig :func:`measure` produces the same :class:`FRF` objects from
a model, with optional measurement noise, so that identification code can be
exercised on data with a known truth.  The thesis sweeps ([Mad]_ sec. 4.3)
were linear sine sweeps from 20 to 1000 Hz in 0.5 Hz steps with a 0.1 A
exciter current at 10 Hz running speed, truncated to 20-225 Hz because the
response above is dominated by noise; :func:`sweep_frequencies` reproduces
that grid.

References
----------
.. [Mad] R. J. Madden, *Identification of unmodeled dynamics in rotor systems
   using mu-synthesis approach*, M.S. thesis, Cleveland State University,
   ch. 4.
.. [Pin] R. Pintelon and J. Schoukens, *System Identification: A Frequency
   Domain Approach*, 2nd ed., Wiley-IEEE Press, 2012, sec. 2.4 (circular
   complex normal noise on FRF measurements).
"""
from __future__ import annotations

import glob as _glob
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from ._validation import AnyOf, Integer, Real, check_param
from .errors import ModelError
from .response import DIRECTIONS, FRF, INPUT_UNITS, OUTPUT_UNITS, FRFFileError, sweep_frequencies
from .uff import dropped_note, is_uff_file, motion_units, read_uff58, reference_units, relabel, units_hint

__all__ = [
    "FRF", "FRFFileError", "Noise", "read_frf", "write_frf", "read_frfs", "measure",
    "sweep_frequencies", "INPUT_UNITS", "OUTPUT_UNITS", "CSV_HEADER", "measure_rotor", "with_noise",
    "THESIS_SWEEP_HZ", "THESIS_ANALYSIS_BAND_HZ", "THESIS_EXCITATION_A", "THESIS_SPEED_HZ",
]

#: CSV header line that separates the ``#`` header from the data.
CSV_HEADER = "freq_hz,re,im"

#: Thesis sine sweep: start, stop, step [Hz] ([Mad]_ sec. 4.3).
THESIS_SWEEP_HZ = (20.0, 1000.0, 0.5)
#: Band kept for the identification (noise above 225 Hz).
THESIS_ANALYSIS_BAND_HZ = (20.0, 225.0)
#: Exciter current amplitude of the sweeps [A].
THESIS_EXCITATION_A = 0.1
#: Running speed during the sweeps [Hz].
THESIS_SPEED_HZ = 10.0

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


# ----------------------------------------------------------------------------
# reading and writing
# ----------------------------------------------------------------------------

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


def read_frf(path, *, mapping=None, units=None) -> FRF:
    """Read one FRF file (format in the module docstring); the response is converted to SI.

    A Universal File (extension ``.uff`` or ``.unv``, or content starting with
    a ``    -1`` line) is read by :func:`mutext.uff.read_uff58` (data set 58,
    velocity and acceleration converted to displacement per force); it must
    hold exactly one FRF -- use :func:`read_frfs` for a file with several.

    Parameters
    ----------
    path : str or os.PathLike
    mapping : dict of int -> int, optional
        For a Universal File only: UFF node -> model station
        (:func:`mutext.uff.read_uff58`; default station = node).
    units : dict of str -> str, optional
        Units labels to read differently, {label in the file: label to read}
        (``output_unit``/``input_unit`` here; the units labels of a Universal
        File).

    Returns
    -------
    FRF
        With ``source`` set to the path.  The units found in the file are
        kept in ``metadata['file_output_unit']`` and
        ``metadata['file_input_unit']``; when the values were changed
        (velocity or acceleration, units other than m per N or A), the
        conversion in ``metadata['conversion']``; what the reader did that the
        user should know (rows at or below 0 Hz dropped, text read as
        Latin-1) in ``metadata['notes']``, a list of str (present only then).

    Raises
    ------
    FRFFileError
        Naming the file, the line (1-based) and the field for: a header line
        not of the form ``# key: value``, a repeated key, a missing required
        key, an unknown quantity or unit (with what to change), a station
        that is not an integer, a missing or wrong CSV header, a row without
        three columns, a value that is not a number or is NaN/infinite, a
        file with no frequency above 0 Hz, a non-positive frequency after the
        first positive one, a non-increasing frequency, and a file without
        data rows; for a Universal File, naming the data set and field
        (:mod:`mutext.uff`), and a file with more than one FRF.  A file that
        is not UTF-8 is read as Latin-1; if it still fails, the error says
        both.

    Examples
    --------
    >>> import os, tempfile
    >>> from mutext.rig import read_frf
    >>> path = os.path.join(tempfile.mkdtemp(), "x13_i12.csv")
    >>> with open(path, "w") as fh:
    ...     _ = fh.write("# input_station: 12\\n# input_quantity: current\\n# input_unit: A\\n"
    ...                  "# output_station: 13\\n# output_quantity: displacement\\n# output_unit: um\\n"
    ...                  "freq_hz,re,im\\n20.0,12.5,-0.31\\n20.5,12.7,-0.33\\n")
    >>> h = read_frf(path)
    >>> h.freq_hz, h.unit                               # micrometres per ampere read as m/A
    (array([20. , 20.5]), 'm/A')
    >>> print(h.response.round(12))
    [1.25e-05-3.1e-07j 1.27e-05-3.3e-07j]
    """
    path = Path(path)
    if is_uff_file(path):
        frfs = read_uff58(path, mapping=mapping, units=units)
        if len(frfs) != 1:
            sets = ", ".join(f["uff_dataset"] for f in (h.metadata for h in frfs))
            raise FRFFileError(path, None, None, f"the Universal File holds {len(frfs)} FRFs (data sets {sets}); "
                                                 f"read_frf reads one -- use read_frfs to read them all")
        return frfs[0]
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise FRFFileError(path, None, None, f"cannot read file: {exc.strerror or exc}") from None
    if b"\x00" in raw:
        raise FRFFileError(path, None, None, "binary file (it contains NUL bytes); an FRF file is UTF-8 text")
    try:
        text = raw.decode("utf-8-sig")
        latin = None
    except UnicodeDecodeError as exc:
        # analyzers and spreadsheets write Latin-1 ('µm', 'm/s²'): read it as such, and say so
        latin = (raw[:exc.start].count(b"\n") + 1, raw[exc.start])
        text = raw.decode("latin-1")
    try:
        frf = _read_csv(path, text, {str(k).strip(): str(v) for k, v in dict(units or {}).items()})
    except FRFFileError as err:
        if latin is None:
            raise
        where = f"line {err.line}: " if err.line is not None else ""
        raise FRFFileError(path, latin[0], err.field,
                           f"not UTF-8 text (byte 0x{latin[1]:02x}), and read as Latin-1 it is no FRF file either: "
                           f"{where}{err.problem}") from None
    if latin is not None:
        frf.metadata.setdefault("notes", []).insert(
            0, f"not UTF-8 text (byte 0x{latin[1]:02x} on line {latin[0]}); read as Latin-1")
    return frf


def _units_error(path, ln, key, raw, what, why, allowed, example):
    return FRFFileError(path, ln, key, f"unknown unit {raw!r} for a {what} ({why}); allowed: {allowed}; "
                                       f"{units_hint(raw, example)}")


def _read_csv(path, text: str, units: dict) -> FRF:
    lines = text.splitlines()
    header: dict[str, tuple[str, int]] = {}
    i = 0
    # --- '# key: value' header
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
    # --- CSV header
    if i >= len(lines):
        raise FRFFileError(path, None, None, f"missing CSV header line {CSV_HEADER!r} "
                                             f"after the '#' header (file ends at line {len(lines)})")
    csv_line = i + 1
    cols = [c.strip().lower() for c in lines[i].split(",")]
    if cols != CSV_HEADER.split(","):
        raise FRFFileError(path, csv_line, None, f"expected the CSV header line {CSV_HEADER!r}, "
                                                 f"got {lines[i].strip()!r}")
    # --- required keys and their values
    for key in _REQUIRED:
        if key not in header:
            raise FRFFileError(path, None, key, f"missing required header key '{key}' "
                                                f"(required: {', '.join(_REQUIRED)})")
    in_station = _parse_int(header["input_station"][0], path, header["input_station"][1],
                            "input_station")
    out_station = _parse_int(header["output_station"][0], path, header["output_station"][1],
                             "output_station")
    in_q, ln = header["input_quantity"]
    if in_q not in INPUT_UNITS:
        raise FRFFileError(path, ln, "input_quantity", f"unknown quantity {in_q!r}; allowed: "
                                                       f"{', '.join(INPUT_UNITS)}")
    in_u, ln = header["input_unit"]
    try:
        in_units = reference_units(relabel(in_u, units))
        if ("force" if in_units.dims[2] else "current") != in_q:
            raise ValueError(f"it is a {'force' if in_units.dims[2] else 'current'}")
    except ValueError as exc:
        raise _units_error(path, ln, "input_unit", in_u, f"{in_q} input", exc, _INPUT_UNIT_NAMES[in_q],
                           "N" if in_q == "force" else "A") from None
    out_q, ln = header["output_quantity"]
    if out_q not in _OUTPUT_QUANTITIES:
        raise FRFFileError(path, ln, "output_quantity", f"unknown quantity {out_q!r}; allowed: "
                                                        f"{', '.join(_OUTPUT_QUANTITIES)}")
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
    speed = None
    if "speed_hz" in header:
        speed = _parse_float(header["speed_hz"][0], path, header["speed_hz"][1], "speed_hz")
    dirs = {}
    for key in ("input_direction", "output_direction"):
        v, ln = header.get(key, ("x", None))
        if v not in DIRECTIONS:
            raise FRFFileError(path, ln, key, f"unknown direction {v!r}; allowed: {', '.join(DIRECTIONS)}")
        dirs[key] = v
    port_names = {key: header[key][0] for key in ("input_name", "output_name") if key in header}
    # --- data rows
    freqs, vals, dropped = [], [], []
    names = CSV_HEADER.split(",")
    for j in range(i + 1, len(lines)):
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
    f_hz = np.array([f for f, _ in freqs])
    G = np.array(vals)
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
    return FRF(freq_hz=f_hz, response=G, input_station=in_station, output_station=out_station, input_quantity=in_q,
               output_quantity="displacement", speed_hz=speed, metadata=meta, source=path, **dirs, **port_names)


def _breaks_line(text: str) -> bool:
    """True if ``text`` holds a character that :meth:`str.splitlines` (the reader)
    treats as a line break (\\n, \\r, \\v, \\f, \\x1c-\\x1e, \\x85, \\u2028, \\u2029)."""
    return len(("x" + text + "x").splitlines()) > 1


def write_frf(path, frf: FRF, *, output_unit: str = "m") -> Path:
    """Write an FRF in the file format of this module.

    Parameters
    ----------
    path : str or os.PathLike
    frf : FRF
        Its stations must be set.  Metadata entries other than the reserved
        keys are written as ``# key: value`` lines (keys and values must be
        single-line; keys may not contain ':'); what a reader noted about the
        file it read (``file_output_unit``, ``file_input_unit``,
        ``conversion``, a ``notes`` list) is not written.
    output_unit : {"m", "mm", "um", "in"}
        Unit of the written response (per N or per A).  Values are written
        with 17 significant digits, so reading back reproduces them to
        rounding (exactly for ``m``).

    Returns
    -------
    pathlib.Path
    """
    path = Path(path)
    if frf.input_station is None or frf.output_station is None:
        raise ModelError(f"write_frf {path}: input_station and output_station must be set "
                         f"(got {frf.input_station}, {frf.output_station})")
    for name in ("input_station", "output_station"):
        v = getattr(frf, name)
        whole = isinstance(v, (int, np.integer)) or (isinstance(v, (float, np.floating)) and float(v).is_integer())
        if isinstance(v, bool) or not whole:
            raise ModelError(f"write_frf {path}: {name} must be a whole station number, got {v!r} "
                             "(it would be written rounded)")
    units = OUTPUT_UNITS[frf.output_quantity]
    if output_unit not in units:
        raise ModelError(f"write_frf {path}: unknown {frf.output_quantity} unit "
                         f"{output_unit!r}; allowed: {', '.join(units)}")
    lines = [
        f"# input_station: {int(frf.input_station)}",
        f"# input_quantity: {frf.input_quantity}",
        f"# input_unit: {frf.input_unit}",
        f"# output_station: {int(frf.output_station)}",
        f"# output_quantity: {frf.output_quantity}",
        f"# output_unit: {output_unit}",
    ]
    if frf.speed_hz is not None:
        lines.append(f"# speed_hz: {float(frf.speed_hz)!r}")
    for key in ("input_direction", "output_direction"):
        if getattr(frf, key) != "x":
            lines.append(f"# {key}: {getattr(frf, key)}")
    for key in ("input_name", "output_name"):
        v = getattr(frf, key)
        if v is not None:
            if not isinstance(v, str) or not v.strip() or _breaks_line(v):
                raise ModelError(f"write_frf {path}: {key} {v!r} cannot be written on one header line")
            lines.append(f"# {key}: {v.strip()}")
    written = {"input_station", "input_quantity", "input_unit", "output_station", "output_quantity",
               "output_unit", "speed_hz", "input_direction", "output_direction", "input_name", "output_name",
               *_PROVENANCE} | set(_RESERVED)
    for k, v in frf.metadata.items():
        if k in _PROVENANCE or k in _RESERVED or (k == "notes" and isinstance(v, (list, tuple))):
            continue
        k, v = str(k), str(v)
        ks = k.strip()
        if ":" in k or _breaks_line(k) or _breaks_line(v) or not ks or ks.startswith("#") \
                or "\x00" in k or "\x00" in v:
            raise ModelError(f"write_frf {path}: metadata key {k!r} / value {v!r} cannot be "
                             f"written as a '# key: value' line")
        if ks in written:
            raise ModelError(f"write_frf {path}: metadata key {k!r} would be written as '{ks}', which "
                             f"is {'a reserved key' if ks in _RESERVED else 'already written'}; the file "
                             f"could not be read back")
        written.add(ks)
        lines.append(f"# {ks}: {v.strip()}")
    lines.append(CSV_HEADER)
    G = frf.response_in(output_unit)
    for f, g in zip(frf.freq_hz, G):
        lines.append(f"{float(f)!r},{float(g.real)!r},{float(g.imag)!r}")
    try:
        path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    except OSError as exc:
        raise FRFFileError(path, None, None, f"cannot write file: {exc.strerror or exc}") from None
    return path


def read_frfs(paths_or_glob, *, mapping=None, units=None) -> list[FRF]:
    """Read several FRF files.

    Parameters
    ----------
    paths_or_glob : str, os.PathLike or iterable of them
        A glob pattern (``"data/cracked_*.frf"``; matches are sorted by
        name), a single path, or a sequence of paths (kept in order).
        A Universal File contributes all its FRF data sets 58, in file order
        (:func:`mutext.uff.read_uff58`).
    mapping : dict of int -> int, optional
        For Universal Files: UFF node -> model station.
    units : dict of str -> str, optional
        Units labels to read differently, {label in the file: label to read}
        (:func:`read_frf`, :func:`mutext.uff.read_uff58`).

    Returns
    -------
    list of FRF
    """
    if isinstance(paths_or_glob, (str, os.PathLike)):
        pattern = os.fspath(paths_or_glob)
        if _glob.has_magic(pattern):
            paths = sorted(_glob.glob(pattern))
            if not paths:
                raise ModelError(f"read_frfs: no file matches the pattern {pattern!r}")
        else:
            paths = [pattern]
    else:
        paths = list(paths_or_glob)
        if not paths:
            raise ModelError("read_frfs: empty list of paths")
    out: list[FRF] = []
    for k, p in enumerate(paths):
        if not isinstance(p, (str, os.PathLike)):
            raise ModelError(f"read_frfs: entry {k} of the list is {type(p).__name__}, not a path")
        if is_uff_file(p):
            out.extend(read_uff58(p, mapping=mapping, units=units))
        else:
            out.append(read_frf(p, units=units))
    return out


# ----------------------------------------------------------------------------
# virtual rig
# ----------------------------------------------------------------------------

@dataclass(frozen=True)
class Noise:
    r"""Measurement noise of the virtual rig.

    At each frequency the measured response is

    .. math::
        \hat G(j\omega) = G(j\omega) + \sigma(\omega)\,\frac{n_r + j n_i}{\sqrt2},
        \qquad \sigma = \text{relative}\cdot|G(j\omega)| + \text{floor},

    with :math:`n_r, n_i` independent standard normal, i.e. circular complex
    Gaussian noise with :math:`E|\hat G - G|^2 = \sigma^2` ([Pin]_).  The
    relative part models the gain/phase scatter of the sine-sweep
    correlation, the floor the sensor noise that dominates away from the
    resonances (the reason for truncating the thesis sweeps at 225 Hz).

    Attributes
    ----------
    relative : float
        Standard deviation relative to :math:`|G|` [-], e.g. 0.01 for 1 %.
    floor : float
        Absolute standard deviation in SI response units (m/N or m/A).
    """
    relative: float = 0.0
    floor: float = 0.0

    def __post_init__(self):
        for name in ("relative", "floor"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0):
                raise ModelError(f"Noise.{name} must be finite and >= 0, got {v}")


def _as_noise(noise) -> Noise | None:
    if noise is None:
        return None
    if isinstance(noise, Noise):
        return noise
    if isinstance(noise, (int, float)):
        return Noise(relative=float(noise))
    if isinstance(noise, (tuple, list)) and len(noise) == 2:
        return Noise(relative=float(noise[0]), floor=float(noise[1]))
    if isinstance(noise, Mapping):
        return Noise(**noise)
    raise ModelError(f"noise must be None, a Noise, a relative level (float) or a pair "
                     f"(relative, floor); got {noise!r}")


def _port_index(spec, labels: Sequence[str], n: int, what: str) -> int:
    if isinstance(spec, (int, np.integer)):
        if not 0 <= spec < n:
            raise ModelError(f"measure: {what} index {spec} is outside 0..{n - 1}")
        return int(spec)
    if isinstance(spec, str):
        if spec not in labels:
            raise ModelError(f"measure: the system has no {what} named {spec!r}; "
                             f"{what}s are {list(labels)}")
        return list(labels).index(spec)
    raise ModelError(f"measure: {what} must be an index or a name, got {spec!r}")


def _response(system, in_port, out_port, omega) -> np.ndarray:
    """Frequency response of one channel at omega [rad/s]."""
    import control as ct

    if isinstance(system, (ct.StateSpace, ct.TransferFunction)) or (
            isinstance(system, tuple) and len(system) == 4):
        from .lti import as_ss, freqresp
        sys = as_ss(system, "measure: system")
        i = _port_index(in_port, sys.input_labels, sys.ninputs, "input")
        o = _port_index(out_port, sys.output_labels, sys.noutputs, "output")
        return freqresp(sys, omega)[o, i, :]
    if callable(system):
        G = np.asarray(system(omega), dtype=complex)
        if G.shape == omega.shape:
            if in_port not in (0, None) or out_port not in (0, None):
                raise ModelError("measure: a callable returning one channel takes in_port=0, out_port=0")
            return G
        if G.ndim == 3 and G.shape[2] == omega.size:
            i = _port_index(in_port, [], G.shape[1], "input")
            o = _port_index(out_port, [], G.shape[0], "output")
            return G[o, i, :]
        raise ModelError(f"measure: the callable returned shape {G.shape}; expected "
                         f"({omega.size},) or (noutputs, ninputs, {omega.size})")
    if hasattr(system, "frequency_response"):      # other python-control LTI objects (FRD, ...)
        G = np.asarray(system.frequency_response(omega, squeeze=False).fresp, dtype=complex)
        i = _port_index(in_port, getattr(system, "input_labels", []), G.shape[1], "input")
        o = _port_index(out_port, getattr(system, "output_labels", []), G.shape[0], "output")
        return G[o, i, :]
    raise ModelError(f"measure: cannot compute a frequency response of a {type(system).__name__}; "
                     f"pass a control.StateSpace/TransferFunction, an (A, B, C, D) tuple or a "
                     f"callable omega[rad/s] -> response")


def measure(system, in_port=0, out_port=0, freq_hz=None, *, noise=None, rng=None,
            input_station: int | None = None, output_station: int | None = None,
            input_quantity: str = "force", output_quantity: str = "displacement",
            speed_hz: float | None = None, metadata: Mapping[str, str] | None = None,
            input_direction: str = "x", output_direction: str = "x") -> FRF:
    r"""Virtual sine-sweep measurement of one channel of a model.

    Parameters
    ----------
    system : control.StateSpace, control.TransferFunction, (A, B, C, D) or callable
        The "rig".  Its response must be in SI units (m/N or m/A).  A callable
        maps angular frequencies [rad/s] to the response, either of shape
        ``(n,)`` (one channel) or ``(noutputs, ninputs, n)``.
    in_port, out_port : int or str
        Channel: index or name (``input_labels`` / ``output_labels``).
    freq_hz : array_like, optional
        Frequencies [Hz]; default :func:`sweep_frequencies` (20-225 Hz,
        0.5 Hz steps, as the truncated thesis sweeps).
    noise : None, float, (relative, floor) or Noise
        Measurement noise (see :class:`Noise`); ``None`` or 0 for exact data.
    rng : numpy.random.Generator or int, optional
        Random generator or seed (for reproducible noise).
    input_station, output_station : int, optional
        Station numbers stored in the FRF (needed to write it to a file).
    input_quantity : {"force", "current"}
    output_quantity : {"displacement"}
    speed_hz : float, optional
        Running speed stored in the FRF [Hz].
    input_direction, output_direction : {"x", "y"}
        Directions stored in the FRF (the plane of a rotor).
    metadata : mapping, optional
        Extra metadata; ``noise_relative`` and ``noise_floor`` are added when
        noise is applied.

    Returns
    -------
    FRF
    """
    f = sweep_frequencies() if freq_hz is None else np.asarray(freq_hz, dtype=float).ravel()
    omega = 2.0 * np.pi * f
    G = _response(system, in_port, out_port, omega)
    meta = {str(k): str(v) for k, v in (metadata or {}).items()}
    nz = _as_noise(noise)
    if nz is not None and (nz.relative > 0 or nz.floor > 0):
        gen = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
        sigma = nz.relative * np.abs(G) + nz.floor
        G = G + sigma * (gen.standard_normal(G.size) + 1j * gen.standard_normal(G.size)) / np.sqrt(2.0)
        meta["noise_relative"] = repr(nz.relative)
        meta["noise_floor"] = repr(nz.floor)
    names = {}
    if isinstance(in_port, str):
        names["input_name"] = in_port
    if isinstance(out_port, str):
        names["output_name"] = out_port
    return FRF(freq_hz=f, response=G, input_station=input_station, output_station=output_station,
               input_quantity=input_quantity, output_quantity=output_quantity, speed_hz=speed_hz,
               metadata=meta, input_direction=input_direction, output_direction=output_direction, **names)


def measure_rotor(model, in_port: str, out_port: str, freq_hz=None, *, noise=None, rng=None,
                  harmonics: int = 6, cutoff_hz: float = 1000.0, revolutions: int = 40,
                  settle_s: float = 0.7, metadata: Mapping[str, str] | None = None,
                  combination: Sequence[int] | None = None, speed_hz: float | None = None,
                  planes: str = "x"):
    r"""Virtual sine sweep of a finite-element rotor, as the rig's analyzer measures it.

    A rotor without a breathing crack is time-invariant: the measurement is
    its exact frequency response (:func:`mutext.rotor.analysis.frf`).  With a
    breathing crack (``breathing = "mayes"``, ``"gasch"`` or ``"gaping"`` in
    the model file) and a running speed, the rotor is time-periodic and the
    measurement is the analyzer's correlation of the response with the
    excitation (:func:`mutext.rotor.periodic.analyzer_frf`: harmonic balance
    with ``harmonics`` terms either side, on the Ritz-reduced model below
    ``cutoff_hz``; the reduction error is stored in the metadata), which
    shows the sidebands a time-invariant model cannot hold.

    With ``combination`` (orders :math:`k`, e.g. ``(-2, -1, 1, 2)``) the
    analyzer also correlates the response at the combination frequencies
    :math:`f + kF` (:func:`mutext.rotor.periodic.analyzer_combination`, the
    off-diagonal harmonic transfer functions: the time-periodic rotor's
    first-order signature); a time-invariant rotor gives zero there.  The
    noise of such a channel is the noise of the excitation-frequency channel
    at the same step in absolute terms, :math:`\sigma = r|\hat H_0| + s`
    (same sensor, same correlation length; the relative level ``r`` is not
    applied to the much smaller combination response, which would make it
    look cleaner than it is).

    With ``planes="xy"`` the rig excites in x and in y at the input's
    station and measures x and y at the output's (two sensors, one sweep per
    excitation plane): the planar FRF matrix :math:`[[H_{xx}, H_{xy}],
    [H_{yx}, H_{yy}]]` of which the directional FRFs are made
    (:mod:`mutext.rotor.directional`: forward and backward whirl, [Lee]_).
    An exciter current drives the y axis with the force per ampere of the
    port's axis (a magnetic bearing has both; the model declares one).  Each
    of the four channels gets its own noise from one generator.

    Parameters
    ----------
    model : mutext.rotor.Rotor
    in_port, out_port : str
        Port names (e.g. ``"i12"``, ``"x13"``); with ``planes="xy"`` also
        station numbers (a unit force; the displacement there).
    freq_hz : array_like, optional
        Default :func:`sweep_frequencies` (20-225 Hz, 0.5 Hz).
    noise, rng
        As in :func:`measure`.
    metadata : mapping, optional
        Extra metadata stored in every FRF recorded.
    harmonics, cutoff_hz, revolutions, settle_s
        Harmonic-balance truncation, reduction cutoff [Hz] and the analyzer's
        correlation length and settling time (thesis: 40 revolutions, 700 ms).
    combination : sequence of int, optional
        Orders :math:`k \ne 0` to record besides the excitation frequency.
    speed_hz : float, optional
        Running speed [Hz] (default: the model's).
    planes : {"x", "xy"}
        ``"x"`` (default): the one channel ``in_port -> out_port``;
        ``"xy"``: the 2 x 2 planar matrix at their stations (not with
        ``combination``).

    Returns
    -------
    FRF, list of FRF with ``combination``, or PlanarFRF with ``planes="xy"``
        With the ports' stations, directions and quantities and the speed.
        With ``combination``: the excitation-frequency FRF first, then one
        per order, whose metadata holds ``order`` and
        ``response_frequency``.  With ``planes="xy"``: a
        :class:`mutext.rotor.directional.PlanarFRF`
        (``.directional()`` gives the dFRFs).

    References
    ----------
    .. [Lee] C.-W. Lee, *Vibration Analysis of Rotors*, Kluwer, 1993, ch. 4.

    Examples
    --------
    >>> from mutext.rotor import load_model, data_path
    >>> P = measure_rotor(load_model(data_path("rotor.toml")), "i12", "x13", [150.0, 190.0], planes="xy")
    >>> [[c.label for c in row] for row in P.channels]
    [['i12->x13', 'i12y->x13'], ['i12->y13', 'i12y->y13']]
    """
    from .rotor.periodic import analyzer_combination, analyzer_frf, periodic_rotor
    f = sweep_frequencies() if freq_hz is None else np.asarray(freq_hz, dtype=float).ravel()
    orders = None
    if combination is not None:
        orders = []
        for k in combination:
            orders.append(int(check_param("measure_rotor", "a combination order (k of f + k F)", k,
                                          AnyOf(Integer(hi=-1), Integer(lo=1)))))
        if not orders or len(set(orders)) != len(orders):
            raise ModelError(f"measure_rotor: combination must list distinct non-zero orders, got {combination!r}")
    speed = None
    if speed_hz is not None:
        check_param("measure_rotor", "speed_hz (the running speed [Hz])", speed_hz, Real(lo=0))
        speed = 2.0 * math.pi * float(speed_hz)
    if planes not in ("x", "xy"):
        raise ModelError(f"measure_rotor: planes must be 'x' (one channel) or 'xy' (the planar 2 x 2 "
                         f"matrix), got {planes!r}")
    if planes == "xy":
        if orders:
            raise ModelError("measure_rotor: combination= records one channel; it does not go with planes='xy'")
        return _measure_planar(model, in_port, out_port, f, speed, speed_hz, noise, rng, harmonics, cutoff_hz,
                               revolutions, settle_s, metadata)
    pr = periodic_rotor(model, inputs=[in_port], outputs=[out_port], speed=speed)
    meta = {str(k): str(v) for k, v in (metadata or {}).items()}
    combos = {}
    if pr.time_invariant():
        H = model.frf(f, inputs=[in_port], outputs=[out_port], **({} if speed is None else {"speed": speed}))
        meta.setdefault("analyzer", "time-invariant model: exact frequency response")
        if orders:
            combos = {k: np.zeros(f.size, complex) for k in orders}
    else:
        red = pr.reduce(cutoff_hz, band_hz=(float(f.min()), float(f.max())))
        H = analyzer_frf(red, f, harmonics=harmonics, revolutions=revolutions, settle_s=settle_s)
        meta.update({"analyzer": f"stepped sine, {revolutions} revolutions per correlation, "
                                 f"{settle_s:g} s settling; harmonic balance N = {harmonics}",
                     "breathing": ", ".join(f"{c.name} {c.law}" for c in pr.cracks),
                     "reduction_error": f"{red.reduction_error:.3g}"})
        if orders:
            combos = {k: v.H[0, 0] for k, v in analyzer_combination(
                red, f, orders, harmonics=harmonics, revolutions=revolutions, settle_s=settle_s).items()}
    ch = H.channel(out_port, in_port)
    if speed is not None:
        ch.speed_hz = float(speed_hz)
    ch.metadata = meta
    if not orders:
        return with_noise(ch, noise, rng=rng)
    gen = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
    main = with_noise(ch, noise, rng=gen)
    out = [main]
    nz = _as_noise(noise)
    F = ch.speed_hz
    for k in orders:
        G = np.asarray(combos[k], complex)
        m = dict(meta, order=str(k), response_frequency=f"f_exc {'+' if k > 0 else '-'} {abs(k)} x {F:g} Hz")
        if nz is not None and (nz.relative > 0 or nz.floor > 0):
            sigma = nz.relative * np.abs(ch.response) + nz.floor
            G = G + sigma * (gen.standard_normal(G.size) + 1j * gen.standard_normal(G.size)) / np.sqrt(2.0)
            m["noise_relative"] = repr(nz.relative)
            m["noise_floor"] = repr(nz.floor)
            m["noise_reference"] = "the excitation-frequency response (absolute noise of the main channel)"
        c = FRF(freq_hz=ch.freq_hz.copy(), response=G, input_station=ch.input_station,
                output_station=ch.output_station, input_quantity=ch.input_quantity,
                output_quantity=ch.output_quantity, speed_hz=F, metadata=m,
                input_direction=ch.input_direction, output_direction=ch.output_direction)
        c.input_name, c.output_name = ch.input_name, ch.output_name
        out.append(c)
    return out


def _measure_planar(model, in_port, out_port, f, speed, speed_hz, noise, rng, harmonics, cutoff_hz,
                    revolutions, settle_s, metadata):
    """The planar 2 x 2 measurement of :func:`measure_rotor` (``planes="xy"``): the same analyzer on
    a rotor with x and y ports at the two stations."""
    from .rotor.directional import PlanarFRF, planar_rotor
    from .rotor.periodic import analyzer_frf, harmonic_response
    pr = planar_rotor(model, in_port, out_port, speed=speed)
    meta = {str(k): str(v) for k, v in (metadata or {}).items()}
    if pr.time_invariant():
        # exact: the k = 0 harmonic of a time-invariant rotor is its frequency response
        H = harmonic_response(pr, f, harmonics=0)(0)
        meta.setdefault("analyzer", "time-invariant model: exact frequency response")
    else:
        red = pr.reduce(cutoff_hz, band_hz=(float(f.min()), float(f.max())))
        H = analyzer_frf(red, f, harmonics=harmonics, revolutions=revolutions, settle_s=settle_s).H
        meta.update({"analyzer": f"stepped sine, {revolutions} revolutions per correlation, "
                                 f"{settle_s:g} s settling; harmonic balance N = {harmonics}",
                     "breathing": ", ".join(f"{c.name} {c.law}" for c in pr.cracks),
                     "reduction_error": f"{red.reduction_error:.3g}"})
    gen = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
    F = float(speed_hz) if speed_hz is not None else (pr.speed / (2 * math.pi) if pr.speed else None)
    rows = []
    for i, o in enumerate(pr.outputs):
        row = []
        for j, q in enumerate(pr.inputs):
            si, di, qi = pr.ports[q]
            so, do, _ = pr.ports[o]
            ch = FRF(freq_hz=f.copy(), response=H[i, j], input_station=si, output_station=so,
                     input_quantity=qi, output_quantity="displacement", speed_hz=F, metadata=dict(meta),
                     input_direction=di, output_direction=do, input_name=q, output_name=o)
            row.append(with_noise(ch, noise, rng=gen))
        rows.append(tuple(row))
    return PlanarFRF(tuple(rows))


def with_noise(frf: FRF, noise=None, *, rng=None) -> FRF:
    """A copy of ``frf`` measured with ``noise`` (as in :func:`measure`: same generator, same
    metadata entries); stations, quantities, directions, names and speed are kept.

    Parameters
    ----------
    frf : FRF
        The exact response.
    noise : None, float, (relative, floor) or Noise
        As in :func:`measure`.
    rng : numpy.random.Generator or int, optional
        Random generator or seed.

    Returns
    -------
    FRF
    """
    out = measure(lambda w: frf.response, 0, 0, frf.freq_hz, noise=noise, rng=rng,
                  input_station=frf.input_station, output_station=frf.output_station,
                  input_quantity=frf.input_quantity, output_quantity=frf.output_quantity,
                  speed_hz=frf.speed_hz, metadata=frf.metadata, input_direction=frf.input_direction,
                  output_direction=frf.output_direction)
    out.input_name, out.output_name = frf.input_name, frf.output_name
    return out
