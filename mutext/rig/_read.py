"""Reading FRF files: one file (:func:`read_frf`; the text is UTF-8, else read as Latin-1 with a note) or
several (:func:`read_frfs`); a Universal File is handed to :func:`mutext.uff.read_uff58`."""
from __future__ import annotations

import glob as _glob
import os
from pathlib import Path

from ..errors import ModelError
from ..response import FRF, FRFFileError
from ..uff import is_uff_file, read_uff58
from ._csv import _read_csv


def read_frf(path, *, mapping=None, units=None) -> FRF:
    """Read one FRF file (format in the docstring of :mod:`mutext.rig`); the response is converted to SI.

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
