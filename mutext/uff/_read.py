"""Reading: the FRF data sets 58 of a Universal File as :class:`mutext.response.FRF` (their values, the
frequencies, the nodes and directions, the metadata; the units of the ordinate are in ``_ordinate``)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ModelError
from ..response import FRF
from ._fields import _ABSCISSA_UNITS, _FUNC_NAMES, _direction, _err, _mutext_tokens, _norm_label, _station
from ._ordinate import _ordinate, _to_displacement
from ._sets import _read_sets, _units_164
from ._units import relabel, units_hint

def read_uff58(path, mapping=None, *, units=None) -> list[FRF]:
    r"""Read the FRF data sets 58 of a Universal File as :class:`FRF` (displacement per force or current, SI).

    Parameters
    ----------
    path : str or os.PathLike
        An ASCII or binary (58b) Universal File; other data sets (e.g. 15,
        2411 geometry) are skipped, a units data set 164 is used for unlabelled
        units.  Header text that is not UTF-8 (an analyzer's Latin-1 ``²`` or
        ``µ``) is read as Latin-1.
    mapping : dict of int -> int, optional
        UFF node -> model station (mass or station number).  Default: the
        station is the node number.  With a mapping, a node not in it is an
        error.
    units : dict of str -> str, optional
        Units labels to read differently, {label in the file: label to read}
        (e.g. ``{"EU/lbf": "g/lbf"}`` for a channel whose sensitivity was
        entered as engineering units); applies to the abscissa, ordinate and
        denominator labels, matched as written or ignoring case and blanks.

    Returns
    -------
    list of FRF
        One per data set 58, in file order, with ``source`` = path,
        ``input_station``/``output_station`` from ``ref_node``/``rsp_node``,
        directions from ``ref_dir``/``rsp_dir``; the response converted to
        m/N (or m/A): velocity divided by :math:`j\omega`, acceleration by
        :math:`-\omega^2` (:math:`\omega = 2\pi f`), units scaled to SI, the
        sign flipped when exactly one direction is negative.  The conversion
        is stated in ``metadata["uff_conversion"]`` (always) and, when the
        values were changed, in ``metadata["conversion"]`` (the same text).
        Lines at or below 0 Hz at the start (an analyzer's 0 Hz line) are
        dropped, and header text read as Latin-1, with a note each in
        ``metadata["notes"]`` (a list of str, present only when there is
        something to note).  ``metadata`` also holds ``uff_dataset``,
        ``uff_rsp_node``, ``uff_rsp_dir``, ``uff_ref_node``, ``uff_ref_dir``,
        ``uff_ordinate`` (quantity and units in the file) and the non-empty ID
        lines ``uff_id1`` .. ``uff_id5``.

    Raises
    ------
    FRFFileError
        Naming the file, the data set and the field (module docstring).
    """
    path = Path(path)
    if mapping is not None:
        try:
            mapping = {int(k): int(v) for k, v in dict(mapping).items()}
        except (TypeError, ValueError):
            raise ModelError(f"read_uff58({path}): mapping must map UFF node numbers to model stations "
                             f"(integers), e.g. {{101: 1}}; got {mapping!r}") from None
    units = {str(k).strip(): str(v) for k, v in dict(units or {}).items()}
    dsets = _read_sets(path)
    u164 = _units_164(dsets)
    out = []
    for i, d in enumerate(dsets):
        if d.get("type") != 58:
            continue
        out.append(_frf_from_dset(path, i + 1, d, mapping, u164, units))
    return out


def drop_non_positive(f_hz) -> int:
    """How many leading frequencies are at or below 0 Hz (an analyzer's 0 Hz line, or negative lines
    before it): the points a reader drops.  All of them if no frequency is above 0 Hz."""
    f = np.asarray(f_hz, dtype=float)
    bad = ~(np.isfinite(f) & (f > 0))
    pos = np.flatnonzero(~bad)
    if pos.size == 0:
        return f.size
    k = int(pos[0])
    return k if np.all(np.isfinite(f[:k])) else 0


def dropped_note(f_dropped, where: str) -> str:
    """The note for lines dropped at the start (``where``: 'point 1', 'line 9', ...)."""
    vals = ", ".join(f"{v:g}" for v in f_dropped)
    what = "the 0 Hz line" if len(f_dropped) == 1 and f_dropped[0] == 0 else \
        f"{len(f_dropped)} line{'s' if len(f_dropped) > 1 else ''} at or below 0 Hz ({vals} Hz)"
    return f"dropped {what} at the start ({where}): an FRF in mutext starts above 0 Hz"


def _frf_from_dset(path, n, d, mapping, u164, units=None) -> FRF:
    """The FRF of data set ``n`` (1-based) of the file ``path``, read from its dict ``d``."""
    units = units or {}
    x, data = _values(path, n, d)
    notes = []
    if d.get("_latin1"):
        notes.append(f"header text not UTF-8 in {', '.join(d['_latin1'])}; read as Latin-1")
    f_hz, data = _frequencies(path, n, d, x, data, units, notes)
    ordinate = _ordinate(path, n, d, units, u164)
    # --- nodes and directions
    out_dir, s_out = _direction(path, n, "rsp_dir", d.get("rsp_dir"))
    in_dir, s_in = _direction(path, n, "ref_dir", d.get("ref_dir"))
    out_st = _station(path, n, "rsp_node", d.get("rsp_node"), mapping)
    in_st = _station(path, n, "ref_node", d.get("ref_node"), mapping)
    # --- conversion
    G, conv, changed = _to_displacement(f_hz, data, ordinate, s_out * s_in)
    meta = _metadata(n, d, ordinate, conv, changed, notes)
    speed, names = _id_tokens(path, n, d)
    return FRF(freq_hz=f_hz, response=G, input_station=in_st, output_station=out_st,
               input_quantity=ordinate.reference, output_quantity="displacement", speed_hz=speed, metadata=meta,
               source=path, input_direction=in_dir, output_direction=out_dir, **names)


def _values(path, n, d) -> tuple[np.ndarray, np.ndarray]:
    """The abscissa and the complex values of a data set that is an FRF (function type 4, complex ordinate)."""
    ft = d.get("func_type")
    if ft != 4:
        raise _err(path, n, "func_type", f"function type {ft} ({_FUNC_NAMES.get(ft, 'not an FRF')}) is not a "
                                         f"frequency response function (4)")
    odt = d.get("ord_data_type")
    if odt not in (5, 6):
        raise _err(path, n, "ord_data_type", f"ordinate data type {odt} is "
                                             f"{'real-only' if odt in (2, 4) else 'unknown'}; an FRF needs complex "
                                             f"values (5 or 6)")
    x = np.asarray(d.get("x"), dtype=float).ravel()
    data = np.asarray(d.get("data"), dtype=complex).ravel()
    if x.size == 0 or x.size != data.size:
        raise _err(path, n, "num_pts", f"{data.size} values for {x.size} abscissa values (header: "
                                       f"{d.get('num_pts')}); the data block is incomplete")
    return x, data


def _frequencies(path, n, d, x, data, units, notes) -> tuple[np.ndarray, np.ndarray]:
    """The abscissa in Hz, strictly increasing and above 0 Hz, and the values at it: lines at or below 0 Hz
    at the start are dropped (with a note appended to ``notes``)."""
    # --- abscissa: frequency [Hz]
    ast = d.get("abscissa_spec_data_type", 0)
    if ast not in (0, 1, 18):
        raise _err(path, n, "abscissa_spec_data_type", f"abscissa specific data type {ast} is not a frequency (18)")
    raw_abs = d.get("abscissa_axis_units_lab")
    alab = _norm_label(relabel(raw_abs, units))
    if alab is not None and alab not in _ABSCISSA_UNITS:
        raise _err(path, n, "abscissa_axis_units_lab", f"unknown abscissa unit {str(raw_abs).strip()!r}; known: Hz, "
                                                       f"rad/s, cpm; {units_hint(raw_abs, 'Hz')}")
    f_hz = x * _ABSCISSA_UNITS[alab or "hz"]
    fld_x = "abscissa_min" if d.get("abscissa_spacing") == 1 else "abscissa"
    k0 = drop_non_positive(f_hz)
    if k0 == f_hz.size:
        raise _err(path, n, fld_x, f"no frequency above 0 Hz (the {f_hz.size} points run from {f_hz[0]:g} to "
                                   f"{f_hz[-1]:g} Hz); an FRF in mutext starts above 0 Hz")
    if k0:
        notes.append(dropped_note(f_hz[:k0], f"point{'s' if k0 > 1 else ''} 1"
                                                      + (f"-{k0}" if k0 > 1 else "")))
        f_hz, data = f_hz[k0:], data[k0:]
    if not np.all(np.isfinite(f_hz)) or np.any(f_hz <= 0):
        k = int(np.argmax(~(np.isfinite(f_hz) & (f_hz > 0))))
        raise _err(path, n, fld_x, f"frequency {f_hz[k]:g} Hz (point {k + k0 + 1}) is not positive; only lines at "
                                   f"the start of the data may be at or below 0 Hz (they are dropped)")
    if np.any(np.diff(f_hz) <= 0):
        k = int(np.argmax(np.diff(f_hz) <= 0))
        raise _err(path, n, "abscissa_inc" if fld_x == "abscissa_min" else fld_x,
                   f"frequencies must be strictly increasing; {f_hz[k + 1]:g} Hz (point {k + k0 + 2}) follows "
                   f"{f_hz[k]:g} Hz")
    if not np.all(np.isfinite(data)):
        k = int(np.argmax(~np.isfinite(data)))
        raise _err(path, n, "data", f"non-finite value at {f_hz[k]:g} Hz")
    return f_hz, data


def _metadata(n, d, ordinate, conv, changed, notes) -> dict:
    """What the FRF of data set ``n`` keeps of the file: the conversion, nodes, directions, ID lines."""
    meta = {"uff_conversion": conv, "uff_dataset": str(n),
            "uff_ordinate": f"{ordinate.quantity} ({ordinate.file_units})",
            "uff_rsp_node": str(d.get("rsp_node")), "uff_rsp_dir": str(d.get("rsp_dir")),
            "uff_ref_node": str(d.get("ref_node")), "uff_ref_dir": str(d.get("ref_dir"))}
    if changed:
        meta["conversion"] = conv
    for k in ("id1", "id2", "id3", "id4", "id5", "rsp_ent_name", "ref_ent_name"):
        v = str(d.get(k, "") or "").strip()
        if v and v.upper() != "NONE":
            meta[f"uff_{k}"] = v
    if notes:
        meta["notes"] = notes
    return meta


def _id_tokens(path, n, d) -> tuple[float | None, dict]:
    """The running speed and the port names written by :func:`mutext.uff.write_uff58` in the ID lines."""
    tokens = {}
    for k in ("id1", "id2", "id3", "id4", "id5"):
        tokens.update(_mutext_tokens(d.get(k)))
    speed = None
    if "speed_hz" in tokens:
        try:
            speed = float(tokens["speed_hz"])
        except ValueError:
            raise _err(path, n, "id2", f"speed_hz={tokens['speed_hz']!r} is not a number") from None
    names = {k: tokens[k] for k in ("input_name", "output_name") if tokens.get(k)}
    return speed, names
