r"""Universal File Format data set 58 (FRFs of modal-test and analyzer software) in and out.

Modal-test systems export measured frequency response functions as
Universal File Format (UFF, ``.uff`` / ``.unv``) data set 58, "function at
nodal DOF", ASCII or binary (58b).  :func:`read_uff58` turns every FRF data set
of such a file into a :class:`mutext.response.FRF` (displacement per force or
per current, SI); :func:`write_uff58` writes FRFs back.  Files are read and
written through the `pyuff <https://github.com/ladisk/pyuff>`_ package.
:func:`mutext.rig.read_frf` and :func:`mutext.rig.read_frfs` dispatch to this
module for a UFF file, so everything that accepts an FRF file accepts UFF 58.

What is read (record and field numbers of data set 58)
------------------------------------------------------
* **Function type** (record 6 field 1, ``func_type``) must be 4, a frequency
  response function.
* **Ordinate** (record 7 field 1, ``ord_data_type``) must be complex (5 or 6);
  a real-only ordinate is refused (the phase is missing).
* **Abscissa** in Hz (record 8: specific data type 18 = frequency, or 0/1;
  units label ``Hz``, ``rad/s`` or ``cpm`` if given), positive and strictly
  increasing; even (record 7: minimum + increment) or uneven spacing.
* **Response** (record 9, ordinate numerator): specific data type 8
  displacement, 11 velocity, 12 acceleration (or 0/1 with a units label).
* **Reference** (record 10, ordinate denominator): specific data type 13
  (excitation force) or 9 (reaction force) -- a force.

  *A current reference* (an exciter or magnetic-bearing coil current; UFF has no
  data type for it) is flagged by the **units label** ``A`` (or ``mA``) of the
  denominator (record 10 field 6, ``orddenom_axis_units_lab``) -- or by an
  ordinate units label ending in ``/A`` -- with the denominator's specific data
  type 0 (unknown) or 1 (general).  :func:`write_uff58` writes a current
  reference that way (type 1, label ``A``).
* **Units** come from the units labels (record 9 and 10 field 6) when given,
  otherwise SI (m, m/s, m/s^2 per N), or the length and force factors of a
  units data set 164 in the same file.  The ordinate label may hold the whole
  ratio (``m/s^2/N``, ``g/N``, ``(m/s2)/N``, ``mm/N``, ``in/lbf``, ``m/A``) or
  only the response unit with the reference unit in the denominator label.
  Known units (case-insensitive): length ``m mm um cm in mil ft``; velocity
  ``<length>/s``; acceleration ``<length>/s^2`` (also ``/s2``) and ``g``
  (9.80665 m/s^2); force ``N kN lbf lb`` (1 lbf = 4.4482216152605 N);
  current ``A mA``.
* **Nodes and directions** (record 6 fields 6, 7, 9, 10: ``rsp_node``,
  ``rsp_dir``, ``ref_node``, ``ref_dir``).  The node is mapped to a model
  station by ``mapping={node: station}`` (default: station = node).  The
  direction +1/-1 (X translation) is ``x``, +2/-2 (Y) is ``y``; a negative
  direction flips the sign of the response (so that it is the response in +x/+y
  to a force in +x/+y).  A Z translation, a rotation or a scalar (0) direction
  is refused.

Conversion to displacement per force (or current) in SI
-------------------------------------------------------
With :math:`\omega = 2\pi f` [rad/s] and the file's values first scaled to SI
(m, m/s or m/s^2 per N or A),

.. math::

    H_d = H_d^{\text{file}}, \qquad
    H_d = \frac{H_v}{j\omega}, \qquad
    H_d = \frac{H_a}{-\omega^2},

times :math:`-1` if exactly one of the two directions is negative.  The
conversion made is stated in ``FRF.metadata["uff_conversion"]``; the file's
nodes, directions, ID lines and entity names are kept in ``metadata``
(``uff_*`` keys).

Errors
------
Every problem raises :class:`mutext.rig.FRFFileError` naming the file, the
data set (1-based position in the file) and the field: not a UFF file, no data
set 58, a function type that is not an FRF, a real-only ordinate, a
non-positive or non-increasing frequency, an unknown unit, a direction that
is not X or Y, a node not in the mapping.

Examples
--------
>>> import numpy as np, tempfile, os
>>> from mutext.response import FRF
>>> from mutext.uff import write_uff58, read_uff58
>>> f = np.arange(1.0, 6.0)
>>> h = FRF(f, 1 / ((2 * np.pi * 3)**2 - (2 * np.pi * f)**2 + 1j * f), input_station=1, output_station=2)
>>> path = os.path.join(tempfile.mkdtemp(), "h.uff")
>>> _ = write_uff58(path, [h], ordinate="acceleration")
>>> g, = read_uff58(path)
>>> (g.input_station, g.output_station), bool(np.allclose(g.response, h.response, rtol=1e-10))
((1, 2), True)
"""
from __future__ import annotations

import math
import os
import re
import warnings
from pathlib import Path

import numpy as np

from .errors import ModelError
from .response import FRF, FRFFileError

__all__ = ["G0", "LBF", "is_uff_file", "read_uff58", "write_uff58"]

#: Standard gravity [m/s^2], the unit ``g``.
G0 = 9.80665
#: One pound-force [N].
LBF = 4.4482216152605

_LENGTH = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "cm": 1e-2, "in": 0.0254, "mil": 2.54e-5, "ft": 0.3048}
#: Response units label -> (quantity, factor to m, m/s or m/s^2).
_RESPONSE_UNITS: dict[str, tuple[str, float]] = {}
for _u, _fac in _LENGTH.items():
    _RESPONSE_UNITS[_u] = ("displacement", _fac)
    _RESPONSE_UNITS[f"{_u}/s"] = ("velocity", _fac)
    _RESPONSE_UNITS[f"{_u}/s^2"] = ("acceleration", _fac)
_RESPONSE_UNITS["g"] = ("acceleration", G0)
#: Reference units label -> (input quantity, factor to N or A).
_REFERENCE_UNITS = {"n": ("force", 1.0), "kn": ("force", 1e3), "lbf": ("force", LBF), "lb": ("force", LBF),
                    "a": ("current", 1.0), "ma": ("current", 1e-3)}
_ABSCISSA_UNITS = {"hz": 1.0, "1/s": 1.0, "rad/s": 1.0 / (2 * math.pi), "cpm": 1.0 / 60.0}

_RESPONSE_TYPES = {8: "displacement", 11: "velocity", 12: "acceleration"}
_REFERENCE_TYPES = {13: "force", 9: "force"}
_TYPE_CODE = {"displacement": 8, "velocity": 11, "acceleration": 12}
_SI_LABEL = {"displacement": "m", "velocity": "m/s", "acceleration": "m/s^2"}
_FUNC_NAMES = {0: "general or unknown", 1: "time response", 2: "auto spectrum", 3: "cross spectrum",
               4: "frequency response function", 5: "transmissibility", 6: "coherence", 9: "PSD",
               12: "spectrum"}
_DIR_NAMES = {0: "scalar", 3: "Z translation", 4: "X rotation", 5: "Y rotation", 6: "Z rotation"}


def _err(path, n, fld, problem):
    return FRFFileError(path, None, fld, problem, dataset=n)


def is_uff_file(path) -> bool:
    """Whether ``path`` is to be read as a Universal File: extension ``.uff``/``.unv`` or content
    starting with a ``    -1`` delimiter line."""
    p = Path(path)
    if p.suffix.lower() in (".uff", ".unv"):
        return True
    try:
        with open(p, "rb") as fh:
            head = fh.read(512)
    except OSError:
        return False
    return head.lstrip(b"\r\n").startswith(b"    -1")


def _norm_label(text) -> str | None:
    """A units label normalised for lookup (lower case, no blanks or parentheses), or None if unused."""
    if text is None:
        return None
    s = str(text).strip()
    if s == "" or s.upper() == "NONE":
        return None
    s = (s.replace("**", "^").replace("\u00b2", "^2").replace("\u00b5", "u").replace("\u03bc", "u")
         .replace("(", "").replace(")", "").replace(" ", "").lower())
    s = re.sub(r"/s2(?![0-9])", "/s^2", s)
    s = s.replace("sec", "s")
    return s


def _parse_ordinate_label(label: str):
    """``label`` -> ((quantity, factor), reference or None); None if unknown."""
    if label in _RESPONSE_UNITS:
        return _RESPONSE_UNITS[label], None
    num, sep, den = label.rpartition("/")
    if sep and num in _RESPONSE_UNITS and den in _REFERENCE_UNITS:
        return _RESPONSE_UNITS[num], _REFERENCE_UNITS[den]
    return None


def _units_164(dsets) -> tuple[float, float, str] | None:
    """Length and force factors (file units -> SI: divide) of the first units data set 164, if any."""
    for d in dsets:
        if isinstance(d, dict) and d.get("type") == 164:
            try:
                return float(d["length"]), float(d["force"]), str(d.get("units_description", "")).strip()
            except (KeyError, TypeError, ValueError):
                return None
    return None


def _mutext_tokens(line) -> dict:
    """``key=value`` tokens of an ID line written by :func:`write_uff58` (``mutext key=value ...``)."""
    s = str(line or "").strip()
    if not s.startswith("mutext "):
        return {}
    out = {}
    for tok in s.split()[1:]:
        k, sep, v = tok.partition("=")
        if sep:
            out[k] = v
    return out


def _direction(path, n, fld, code):
    try:
        c = int(code)
    except (TypeError, ValueError):
        raise _err(path, n, fld, f"direction {code!r} is not an integer") from None
    if abs(c) == 1:
        return "x", (1 if c > 0 else -1)
    if abs(c) == 2:
        return "y", (1 if c > 0 else -1)
    name = _DIR_NAMES.get(abs(c), "unknown")
    raise _err(path, n, fld, f"direction {c} ({name}) is not X (+/-1) or Y (+/-2); mutext models the "
                             f"plane of a rotor or a chain (x, y) only")


def _station(path, n, fld, node, mapping):
    try:
        node = int(node)
    except (TypeError, ValueError):
        raise _err(path, n, fld, f"node {node!r} is not an integer") from None
    if mapping is None:
        return node
    if node not in mapping:
        raise _err(path, n, fld, f"node {node} is not in the node -> station mapping "
                                 f"(nodes mapped: {', '.join(str(k) for k in sorted(mapping))})")
    return int(mapping[node])


def _read_sets(path):
    import pyuff
    path = Path(path)
    if not path.is_file():
        raise _err(path, None, None, "cannot read file: no such file")
    try:
        uf = pyuff.UFF(os.fspath(path))
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
        except Exception as exc:  # noqa: BLE001 (pyuff raises bare Exception)
            raise _err(path, i + 1, None, f"cannot read data set {t} (pyuff: {exc}); a binary 58b file from "
                                          f"some software can be repaired with pyuff.fix_58b") from None
        dsets.append(d)
    return dsets


def read_uff58(path, mapping=None) -> list[FRF]:
    r"""Read the FRF data sets 58 of a Universal File as :class:`FRF` (displacement per force or current, SI).

    Parameters
    ----------
    path : str or os.PathLike
        An ASCII or binary (58b) Universal File; other data sets (e.g. 15,
        2411 geometry) are skipped, a units data set 164 is used for unlabelled
        units.
    mapping : dict of int -> int, optional
        UFF node -> model station (mass or station number).  Default: the
        station is the node number.  With a mapping, a node not in it is an
        error.

    Returns
    -------
    list of FRF
        One per data set 58, in file order, with ``source`` = path,
        ``input_station``/``output_station`` from ``ref_node``/``rsp_node``,
        directions from ``ref_dir``/``rsp_dir``; the response converted to
        m/N (or m/A): velocity divided by :math:`j\omega`, acceleration by
        :math:`-\omega^2` (:math:`\omega = 2\pi f`), units scaled to SI, the
        sign flipped when exactly one direction is negative.  The conversion
        is stated in ``metadata["uff_conversion"]``; ``metadata`` also holds
        ``uff_dataset``, ``uff_rsp_node``, ``uff_rsp_dir``, ``uff_ref_node``,
        ``uff_ref_dir``, ``uff_ordinate`` (quantity and units in the file) and
        the non-empty ID lines ``uff_id1`` .. ``uff_id5``.

    Raises
    ------
    FRFFileError
        Naming the file, the data set and the field (module docstring).
    """
    path = Path(path)
    if mapping is not None:
        mapping = {int(k): int(v) for k, v in dict(mapping).items()}
    dsets = _read_sets(path)
    u164 = _units_164(dsets)
    out = []
    for i, d in enumerate(dsets):
        if d.get("type") != 58:
            continue
        out.append(_frf_from_dset(path, i + 1, d, mapping, u164))
    return out


def _frf_from_dset(path, n, d, mapping, u164) -> FRF:
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
    # --- abscissa: frequency [Hz]
    ast = d.get("abscissa_spec_data_type", 0)
    if ast not in (0, 1, 18):
        raise _err(path, n, "abscissa_spec_data_type", f"abscissa specific data type {ast} is not a frequency (18)")
    alab = _norm_label(d.get("abscissa_axis_units_lab"))
    if alab is not None and alab not in _ABSCISSA_UNITS:
        raise _err(path, n, "abscissa_axis_units_lab", f"unknown abscissa unit {d.get('abscissa_axis_units_lab')!r}; "
                                                       f"known: Hz, rad/s, cpm")
    f_hz = x * _ABSCISSA_UNITS[alab or "hz"]
    fld_x = "abscissa_min" if d.get("abscissa_spacing") == 1 else "abscissa"
    if not np.all(np.isfinite(f_hz)) or np.any(f_hz <= 0):
        k = int(np.argmax(~(np.isfinite(f_hz) & (f_hz > 0))))
        raise _err(path, n, fld_x, f"frequency {f_hz[k]:g} Hz (point {k + 1}) is not positive; an FRF in "
                                   f"mutext starts above 0 Hz (drop the 0 Hz line)")
    if np.any(np.diff(f_hz) <= 0):
        k = int(np.argmax(np.diff(f_hz) <= 0))
        raise _err(path, n, "abscissa_inc" if fld_x == "abscissa_min" else fld_x,
                   f"frequencies must be strictly increasing; {f_hz[k + 1]:g} Hz (point {k + 2}) follows "
                   f"{f_hz[k]:g} Hz")
    if not np.all(np.isfinite(data)):
        k = int(np.argmax(~np.isfinite(data)))
        raise _err(path, n, "data", f"non-finite value at {f_hz[k]:g} Hz")
    # --- units of the ordinate
    rst = d.get("ordinate_spec_data_type", 0)
    dst = d.get("orddenom_spec_data_type", 0)
    if rst not in (0, 1) and rst not in _RESPONSE_TYPES:
        raise _err(path, n, "ordinate_spec_data_type", f"ordinate specific data type {rst} is not displacement (8), "
                                                       f"velocity (11) or acceleration (12)")
    if dst not in (0, 1) and dst not in _REFERENCE_TYPES:
        raise _err(path, n, "orddenom_spec_data_type", f"ordinate denominator specific data type {dst} is not a "
                                                       f"force (13 excitation, 9 reaction) or a current (0/1 with "
                                                       f"units label 'A')")
    raw_num = d.get("ordinate_axis_units_lab")
    raw_den = d.get("orddenom_axis_units_lab")
    num, den = _norm_label(raw_num), _norm_label(raw_den)
    resp = ref = None
    if num is not None:
        parsed = _parse_ordinate_label(num)
        if parsed is None:
            raise _err(path, n, "ordinate_axis_units_lab",
                       f"unknown unit {str(raw_num).strip()!r}; known: displacement m, mm, um, in ..., velocity "
                       f"<length>/s, acceleration <length>/s^2 or g, optionally per N, kN, lbf, A, mA "
                       f"(e.g. 'm/s^2/N', 'g/N')")
        resp, ref = parsed
    if den is not None:
        if den not in _REFERENCE_UNITS:
            raise _err(path, n, "orddenom_axis_units_lab", f"unknown unit {str(raw_den).strip()!r}; known: N, kN, "
                                                           f"lbf, lb (force), A, mA (current)")
        if ref is not None and _REFERENCE_UNITS[den] != ref:
            raise _err(path, n, "orddenom_axis_units_lab", f"units {str(raw_den).strip()!r} contradict the ordinate "
                                                           f"label {str(raw_num).strip()!r}")
        ref = _REFERENCE_UNITS[den]
    length_f, force_f = 1.0, 1.0
    sysname = "SI"
    if u164 is not None:
        length_f, force_f = 1.0 / u164[0], 1.0 / u164[1]
        sysname = f"data set 164 units {u164[2] or '?'} (length x {length_f:g}, force x {force_f:g})"
    if resp is None:
        if rst not in _RESPONSE_TYPES:
            raise _err(path, n, "ordinate_spec_data_type", f"unknown response quantity (specific data type {rst}) "
                                                           f"and no units label; cannot tell displacement, velocity "
                                                           f"or acceleration")
        resp = (_RESPONSE_TYPES[rst], length_f)
    elif rst in _RESPONSE_TYPES and _RESPONSE_TYPES[rst] != resp[0]:
        raise _err(path, n, "ordinate_spec_data_type", f"specific data type {rst} ({_RESPONSE_TYPES[rst]}) "
                                                       f"contradicts the units label {str(raw_num).strip()!r} "
                                                       f"({resp[0]})")
    if ref is None:
        if dst not in _REFERENCE_TYPES:
            raise _err(path, n, "orddenom_spec_data_type", f"unknown reference quantity (specific data type {dst}) "
                                                           f"and no units label; label 'N' for a force, 'A' for a "
                                                           f"current")
        ref = ("force", force_f)
    elif dst in _REFERENCE_TYPES and ref[0] != "force":
        raise _err(path, n, "orddenom_spec_data_type", f"specific data type {dst} (force) contradicts the "
                                                       f"reference units ({ref[0]})")
    quantity, rfac = resp
    in_q, ffac = ref
    # --- nodes and directions
    out_dir, s_out = _direction(path, n, "rsp_dir", d.get("rsp_dir"))
    in_dir, s_in = _direction(path, n, "ref_dir", d.get("ref_dir"))
    out_st = _station(path, n, "rsp_node", d.get("rsp_node"), mapping)
    in_st = _station(path, n, "ref_node", d.get("ref_node"), mapping)
    # --- conversion
    w = 2 * np.pi * f_hz
    G = data * (rfac / ffac)
    in_unit = "N" if in_q == "force" else "A"
    steps = []
    file_units = (str(raw_num).strip() if num is not None else f"{_SI_LABEL[quantity]} [{sysname}]")
    if den is not None:
        file_units += f" / {str(raw_den).strip()}"
    if rfac / ffac != 1.0:
        steps.append(f"scaled by {rfac / ffac:.12g} to {_SI_LABEL[quantity]}/{in_unit}")
    if quantity == "velocity":
        G = G / (1j * w)
        steps.append("divided by j*omega")
    elif quantity == "acceleration":
        G = G / (-(w ** 2))
        steps.append("divided by -omega^2")
    sign = s_out * s_in
    if sign < 0:
        G = -G
        steps.append("sign flipped (one negative direction)")
    conv = (f"{quantity} per {in_q} in the file ({file_units}) -> displacement per {in_q} m/{in_unit}: "
            + (", ".join(steps) if steps else "unchanged") + "; omega = 2*pi*f [rad/s]")
    meta = {"uff_conversion": conv, "uff_dataset": str(n), "uff_ordinate": f"{quantity} ({file_units})",
            "uff_rsp_node": str(d.get("rsp_node")), "uff_rsp_dir": str(d.get("rsp_dir")),
            "uff_ref_node": str(d.get("ref_node")), "uff_ref_dir": str(d.get("ref_dir"))}
    for k in ("id1", "id2", "id3", "id4", "id5", "rsp_ent_name", "ref_ent_name"):
        v = str(d.get(k, "") or "").strip()
        if v and v.upper() != "NONE":
            meta[f"uff_{k}"] = v
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
    return FRF(freq_hz=f_hz, response=G, input_station=in_st, output_station=out_st, input_quantity=in_q,
               output_quantity="displacement", speed_hz=speed, metadata=meta, source=path,
               input_direction=in_dir, output_direction=out_dir, **names)


def _fmt13(v: float) -> float:
    """``v`` as the ASCII abscissa format E13.5 stores it."""
    return float(f"{v:13.5e}")


def write_uff58(path, frfs, *, ordinate: str = "displacement", binary: bool = False, mapping=None) -> Path:
    r"""Write FRFs as Universal File data sets 58 (one per FRF, function type 4), through ``pyuff``.

    Parameters
    ----------
    path : str or os.PathLike
        Overwritten.
    frfs : FRF or sequence of FRF
        Stations must be set.  Written in order.
    ordinate : {"displacement", "velocity", "acceleration"}
        Response written: displacement per force (m/N; per current m/A), or
        :math:`j\omega H` (m/s/N) or :math:`-\omega^2 H` (m/s^2/N).  The
        specific data types (8/11/12 over 13, or over 1 with units label ``A``
        for a current) and the units labels are written.
    binary : bool
        Binary 58b (values and abscissa in double precision, exact round trip)
        instead of ASCII.  ASCII data set 58 stores values with 12 significant
        digits (format E20.12) and the abscissa in E13.5: an evenly spaced
        grid whose start and step have at most 6 significant digits (e.g.
        20 Hz in 0.5 Hz steps) is exact; otherwise a warning states the
        largest change of a frequency.
    mapping : dict of int -> int, optional
        The node -> station mapping of :func:`read_uff58`; written nodes are
        the nodes of the stations (default node = station).

    Returns
    -------
    pathlib.Path

    Notes
    -----
    ID line 1 holds the channel label, ID line 2 ``mutext speed_hz=...
    input_name=... output_name=...`` (read back by :func:`read_uff58`).
    Directions: ``x`` is +1, ``y`` is +2.
    """
    import pyuff
    path = Path(path)
    if isinstance(frfs, FRF):
        frfs = [frfs]
    frfs = list(frfs)
    if not frfs:
        raise ModelError(f"write_uff58 {path}: no FRF to write")
    if ordinate not in _TYPE_CODE:
        raise ModelError(f"write_uff58 {path}: ordinate must be one of {', '.join(_TYPE_CODE)}, got {ordinate!r}")
    node_of = None
    if mapping is not None:
        node_of = {}
        for node, st in dict(mapping).items():
            node_of.setdefault(int(st), int(node))
    dsets = []
    for k, h in enumerate(frfs):
        if not isinstance(h, FRF):
            raise ModelError(f"write_uff58 {path}: item {k} is not an FRF")
        if h.input_station is None or h.output_station is None:
            raise ModelError(f"write_uff58 {path}: FRF {k} ({h.label}): input_station and output_station must "
                             f"be set")
        nodes = []
        for st in (h.output_station, h.input_station):
            if node_of is None:
                nodes.append(int(st))
            elif int(st) in node_of:
                nodes.append(node_of[int(st)])
            else:
                raise ModelError(f"write_uff58 {path}: station {st} of FRF {k} is not in the node mapping")
        f = np.asarray(h.freq_hz, dtype=float)
        w = 2 * np.pi * f
        G = h.response.copy()
        if ordinate == "velocity":
            G = G * (1j * w)
        elif ordinate == "acceleration":
            G = G * (-(w ** 2))
        even = False
        if not binary and f.size > 1:
            df = (f[-1] - f[0]) / (f.size - 1)
            df13, f013 = _fmt13(df), _fmt13(f[0])
            even = bool(np.allclose(f013 + np.arange(f.size) * df13, f, rtol=1e-13, atol=0.0))
            if not even:
                change = float(np.max(np.abs(np.array([_fmt13(v) for v in f]) - f) / f))
                if change > 1e-13:
                    warnings.warn(f"write_uff58 {path}: FRF {k} ({h.label}): the ASCII abscissa (E13.5) changes "
                                  f"frequencies by up to {change:.1e} (relative); use binary=True for an exact "
                                  f"abscissa", UserWarning, stacklevel=2)
        in_unit = "N" if h.input_quantity == "force" else "A"
        tokens = ["mutext"]
        if h.speed_hz is not None:
            tokens.append(f"speed_hz={float(h.speed_hz)!r}")
        for key in ("input_name", "output_name"):
            v = getattr(h, key)
            if v is not None and re.fullmatch(r"[^\s=]+", str(v)):
                tokens.append(f"{key}={v}")
        id2 = " ".join(tokens) if len(tokens) > 1 else "NONE"
        if len(id2) > 80:
            id2 = " ".join(tokens[:2])
        label = f"{h.label} ({ordinate}/{h.input_quantity}, mutext)"[:80]
        d = pyuff.prepare_58(
            binary=1 if binary else 0, id1=label, id2=id2, id3="NONE", id4="NONE", id5="NONE",
            func_type=4, ver_num=0, load_case_id=0,
            rsp_ent_name="NONE", rsp_node=nodes[0], rsp_dir=1 if h.output_direction == "x" else 2,
            ref_ent_name="NONE", ref_node=nodes[1], ref_dir=1 if h.input_direction == "x" else 2,
            abscissa_spacing=1 if even else 0,
            abscissa_spec_data_type=18, abscissa_len_unit_exp=0, abscissa_force_unit_exp=0,
            abscissa_temp_unit_exp=0, abscissa_axis_units_lab="Hz",
            ordinate_spec_data_type=_TYPE_CODE[ordinate], ordinate_len_unit_exp=1, ordinate_force_unit_exp=0,
            ordinate_temp_unit_exp=0, ordinate_axis_units_lab=_SI_LABEL[ordinate],
            orddenom_spec_data_type=13 if h.input_quantity == "force" else 1,
            orddenom_len_unit_exp=0, orddenom_force_unit_exp=1 if h.input_quantity == "force" else 0,
            orddenom_temp_unit_exp=0, orddenom_axis_units_lab=in_unit,
            z_axis_spec_data_type=0, z_axis_value=0.0,
            data=np.asarray(G, dtype=complex), x=f)
        d["ord_data_type"] = 6
        dsets.append(d)
    try:
        path.write_bytes(b"")       # pyuff's binary writer truncates the file in 'overwrite' mode: always add
        with warnings.catch_warnings():
            # pyuff's binary writer drops (without closing) the text handle it reopens after the data
            warnings.simplefilter("ignore", ResourceWarning)
            pyuff.UFF(os.fspath(path)).write_sets(dsets, mode="add")
    except Exception as exc:  # noqa: BLE001 (pyuff raises bare Exception)
        raise ModelError(f"write_uff58 {path}: pyuff could not write the file: {exc}") from None
    return path
