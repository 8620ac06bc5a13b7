"""Writing an FRF file in the format of :mod:`mutext.rig` (the values in SI or in the output unit asked for)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ModelError
from ..response import FRF, OUTPUT_UNITS, FRFFileError
from ._format import _PROVENANCE, _RESERVED, CSV_HEADER


def _breaks_line(text: str) -> bool:
    """True if ``text`` holds a character that :meth:`str.splitlines` (the reader)
    treats as a line break (\\n, \\r, \\v, \\f, \\x1c-\\x1e, \\x85, \\u2028, \\u2029)."""
    return len(("x" + text + "x").splitlines()) > 1


def write_frf(path, frf: FRF, *, output_unit: str = "m") -> Path:
    """Write an FRF in the file format of :mod:`mutext.rig`.

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
