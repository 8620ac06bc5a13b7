"""A Universal File read into its data sets (dicts, through ``pyuff``): which files are Universal Files,
header text in Latin-1 re-encoded for pyuff, and the units data set 164."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

from ._fields import _err

def is_uff_file(path) -> bool:
    """Whether ``path`` is to be read as a Universal File: extension ``.uff``/``.unv`` or content
    starting with a ``    -1`` delimiter line.

    Parameters
    ----------
    path : str or path-like
        The file.
    """
    p = Path(path)
    if p.suffix.lower() in (".uff", ".unv"):
        return True
    try:
        with open(p, "rb") as fh:
            head = fh.read(512)
    except OSError:
        return False
    return head.lstrip(b"\r\n").startswith(b"    -1")


def _units_164(dsets) -> tuple[float, float, str] | None:
    """Length and force factors (file units -> SI: divide) of the first units data set 164, if any."""
    for d in dsets:
        if isinstance(d, dict) and d.get("type") == 164:
            try:
                return float(d["length"]), float(d["force"]), str(d.get("units_description", "")).strip()
            except (KeyError, TypeError, ValueError):
                return None
    return None


#: header line (0-based, the '    -1' line first) of a data set 58 -> what it holds
_HEADER_RECORDS = {2: "ID line 1", 3: "ID line 2", 4: "ID line 3", 5: "ID line 4", 6: "ID line 5",
                   7: "record 6 (entity names, nodes)", 8: "record 7", 9: "record 8 (abscissa units label)",
                   10: "record 9 (ordinate units label)", 11: "record 10 (denominator units label)",
                   12: "record 11 (z-axis units label)"}


def _blocks(raw: bytes) -> list[tuple[int, int]]:
    """(start, end) byte offsets of the data sets of a Universal File, found as pyuff finds them: a
    '    -1' delimiter line opens a data set, the next one closes it (end = offset of the closing line)."""
    marks, i = [], -1
    while True:
        i = raw.find(b"    -1", i + 1)
        if i == -1:
            break
        nxt = raw[i + 6:i + 7]
        if nxt in (b"", b"\n", b"\r") or raw[i + 6:i + 80] == b" " * 74:
            marks.append(i)
    return list(zip(marks[0::2], marks[1::2]))


def _latin1_headers(raw: bytes) -> tuple[bytes, dict[int, list[str]]]:
    """``raw`` with every header line of a data set 58 that is not UTF-8 re-encoded from Latin-1 (one byte,
    one character: the fixed columns stay where they were) to UTF-8, and the records so read per data set
    (1-based).  Analyzers write their ID lines and units labels (``(1/N)*(m/s\u00b2)``) in Latin-1."""
    out, pos, found = [], 0, {}
    for k, (si, ei) in enumerate(_blocks(raw)):
        lines = raw[si:ei].splitlines(True)
        try:
            if len(lines) < 3 or int(lines[1][:6]) != 58:
                continue
        except ValueError:
            continue
        changed = []
        for j in range(2, min(13, len(lines))):
            try:
                lines[j].decode("utf-8")
            except UnicodeDecodeError:
                lines[j] = lines[j].decode("latin-1").encode("utf-8")
                changed.append(_HEADER_RECORDS[j])
        if changed:
            out += [raw[pos:si], b"".join(lines)]
            pos = ei
            found[k + 1] = changed
    out.append(raw[pos:])
    return b"".join(out), found


def _read_sets(path):
    path = Path(path)
    if not path.is_file():
        raise _err(path, None, None, "cannot read file: no such file")
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise _err(path, None, None, f"cannot read file: {exc.strerror or exc}") from None
    fixed, latin = _latin1_headers(raw)
    if not latin:
        return _pyuff_sets(path, path, latin)
    # pyuff decodes as UTF-8: hand it the header lines re-encoded (a copy; the file is left alone)
    with tempfile.TemporaryDirectory(prefix="mutext-uff-") as tmp:
        copy = Path(tmp) / path.name
        copy.write_bytes(fixed)
        return _pyuff_sets(copy, path, latin)


def _pyuff_sets(read_path, path, latin):
    import pyuff
    try:
        uf = pyuff.UFF(os.fspath(read_path))
        n_sets = uf.get_n_sets()
        types = [int(t) for t in np.atleast_1d(uf.get_set_types())]
    except Exception as exc:  # noqa: BLE001 (pyuff raises bare Exception)
        raise _err(path, None, None, f"not a Universal File (pyuff: {exc})") from None
    if n_sets == 0:
        raise _err(path, None, None, "not a Universal File: no data set between '    -1' delimiter lines")
    if 58 not in types:
        raise _err(path, None, None, f"no data set 58 (function at nodal DOF) in the file; data set types "
                                     f"found: {', '.join(str(t) for t in types)}")
    dsets = []
    for i, t in enumerate(types):
        if t not in (58, 164):
            dsets.append({"type": t})
            continue
        try:
            d = uf.read_sets(i)
        except Exception as exc:  # noqa: BLE001 (pyuff raises bare Exception, or a UnicodeDecodeError)
            raise _err(path, i + 1, None, f"cannot read data set {t} (pyuff: {exc}); a binary 58b file from "
                                          f"some software can be repaired with pyuff.fix_58b") from None
        if i + 1 in latin:
            d["_latin1"] = latin[i + 1]
        dsets.append(d)
    return dsets
