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
  units label ``Hz``, ``rad/s`` or ``cpm`` if given), strictly increasing;
  even (record 7: minimum + increment) or uneven spacing.  Lines at or below
  0 Hz at the start (analyzers export the 0 Hz line) are dropped with a note;
  a file with no line above 0 Hz is an error.
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
  ratio (``m/s^2/N``, ``(1/N)*(m/s²)``, ``g/N``, ``(m/s2)/N``, ``mm/N``,
  ``in/lbf``, ``in/s/lbf``, ``m/A``) or only the response unit with the
  reference unit in the denominator label.  A label is read as a product of
  powers of known units (:func:`parse_units`; case-insensitive, ``µ`` = ``u``,
  exponents as ``^2``, ``**2``, ``²``, ``s2``): length ``m mm um cm in mil
  ft``, time ``s``, ``g`` (9.80665 m/s^2), force ``N kN lbf lb`` (1 lbf =
  4.4482216152605 N), current ``A mA``; it must come out as a displacement,
  velocity or acceleration per force or current.  An unknown label is an error
  naming the data set, the field and the label; ``units={label: label to
  read}`` says how to read it (``mutext frf ... --units LABEL=UNIT``).
* **Text that is not UTF-8** in the header (ID lines, entity names, units
  labels: analyzers write Latin-1, e.g. the byte 0xB2 for ``²``) is read as
  Latin-1, with a note.
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
conversion made is stated in ``FRF.metadata["uff_conversion"]`` (what the file
holds, in what units, and each step: the scale factor with the definitions of
the units it comes from, e.g. ``g = 9.80665 m/s^2``, ``lbf = 4.4482216152605
N``, the division by :math:`j\omega` or :math:`-\omega^2`, a sign flip), and
also in ``metadata["conversion"]`` when the values were changed (the key
every reader uses, :mod:`mutext.rig`).  What the reader did that the user
should know (a 0 Hz line dropped, Latin-1 text) is in
``metadata["notes"]``, a list of str.  The file's nodes, directions, ID lines
and entity names are kept in ``metadata`` (``uff_*`` keys).

Errors
------
Every problem raises :class:`mutext.rig.FRFFileError` naming the file, the
data set (1-based position in the file) and the field: not a UFF file, no data
set 58, a function type that is not an FRF, a real-only ordinate, no frequency
above 0 Hz or a non-increasing frequency, an unknown unit (with what to
change), a direction that is not X or Y, a node not in the mapping.

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
import tempfile
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ._validation import Options, validate_params
from .errors import ModelError
from .response import FRF, FRFFileError

__all__ = ["G0", "LBF", "KNOWN_UNITS", "Units", "is_uff_file", "parse_units", "read_uff58", "write_uff58"]

#: Standard gravity [m/s^2], the unit ``g``.
G0 = 9.80665
#: One pound-force [N].
LBF = 4.4482216152605

# --- units labels -------------------------------------------------------------------------------------------
# A label is read as a product of powers of the units below (dimension exponents of length, time, force,
# current); the ordinate is motion (m, m/s, m/s^2) per force or current.

_DIMS = ("length", "time", "force", "current")
#: atom (lower case) -> (factor to SI, (length, time, force, current) exponents, definition shown in records)
_ATOMS: dict[str, tuple[float, tuple[int, int, int, int], str | None]] = {
    "m": (1.0, (1, 0, 0, 0), None),
    "mm": (1e-3, (1, 0, 0, 0), "mm = 0.001 m"),
    "um": (1e-6, (1, 0, 0, 0), "um = 1e-06 m"),
    "cm": (1e-2, (1, 0, 0, 0), "cm = 0.01 m"),
    "in": (0.0254, (1, 0, 0, 0), "in = 0.0254 m"),
    "inch": (0.0254, (1, 0, 0, 0), "in = 0.0254 m"),
    "mil": (2.54e-5, (1, 0, 0, 0), "mil = 2.54e-05 m"),
    "ft": (0.3048, (1, 0, 0, 0), "ft = 0.3048 m"),
    "s": (1.0, (0, 1, 0, 0), None),
    "sec": (1.0, (0, 1, 0, 0), None),
    "g": (G0, (1, -2, 0, 0), f"g = {G0!r} m/s^2"),
    "n": (1.0, (0, 0, 1, 0), None),
    "kn": (1e3, (0, 0, 1, 0), "kN = 1000 N"),
    "lbf": (LBF, (0, 0, 1, 0), f"lbf = {LBF!r} N"),
    "lb": (LBF, (0, 0, 1, 0), f"lb = {LBF!r} N (pound-force)"),
    "a": (1.0, (0, 0, 0, 1), None),
    "ma": (1e-3, (0, 0, 0, 1), "mA = 0.001 A"),
}
_RESPONSE_DIMS = {(1, 0): "displacement", (1, -1): "velocity", (1, -2): "acceleration"}
_REFERENCE_DIMS = {(-1, 0): "force", (0, -1): "current"}
_SUPERSCRIPTS = str.maketrans("\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078\u2079\u207b\u207a",
                              "0123456789-+")
#: what a units error lists as known
KNOWN_UNITS = ("displacement m, mm, um (µm), cm, in, mil, ft; velocity <length>/s; acceleration <length>/s^2 "
               "(also s², s2, s**2) or g; per force N, kN, lbf, lb or per current A, mA; written as "
               "'m/s^2/N', '(m/s²)/N', '(1/N)*(m/s²)', 'm/(N*s^2)', 'm s^-2 N^-1', 'g/lbf', 'in/s/lbf', 'um/N'")

_TOKEN = re.compile(r"\s*(?:(?P<atom>[a-z]+)(?P<exp>[0-9]+)?|(?P<one>1)(?![0-9.])|(?P<op>\^[+-]?[0-9]+|[*/()]))")


@dataclass(frozen=True)
class Units:
    """A units label read as a product of powers of known units.

    Attributes
    ----------
    label : str
        The label as given.
    factor : float
        Multiply a value in these units by ``factor`` to get SI (m, s, N, A).
    dims : tuple of 4 int
        Exponents of length, time, force and current.
    definitions : tuple of str
        The non-SI units used, as ``"g = 9.80665 m/s^2"``.
    reference_factor : float
        The part of ``factor`` that comes from the force and current units
        (``1/4.448...`` for ``in/lbf``).
    """
    label: str
    factor: float
    dims: tuple
    definitions: tuple = ()
    reference_factor: float = 1.0

    @property
    def quantity(self) -> str | None:
        """``displacement``, ``velocity`` or ``acceleration`` (motion per force or current), None without
        length and time; ``"?"`` if the length and time exponents are not those of a motion."""
        L, T, F, I = self.dims
        if (L, T) == (0, 0):
            return None
        return _RESPONSE_DIMS.get((L, T), "?")

    @property
    def reference(self) -> str | None:
        """``force`` or ``current`` if the label is per force / per current, None if per nothing,
        ``"?"`` otherwise (e.g. force times a length)."""
        L, T, F, I = self.dims
        if (F, I) == (0, 0):
            return None
        return _REFERENCE_DIMS.get((F, I), "?")


def _normalise(text: str) -> str:
    s = str(text).strip()
    s = re.sub(r"[\u2070\u00b9\u00b2\u00b3\u2074-\u2079\u207a\u207b]+",
               lambda m: "^" + m.group(0).translate(_SUPERSCRIPTS), s)
    s = (s.replace("**", "^").replace("\u00b5", "u").replace("\u03bc", "u").replace("\u00b7", "*")
         .replace("\u22c5", "*").replace("\u00d7", "*").replace("[", "(").replace("]", ")"))
    return s.lower()


def parse_units(label) -> Units:
    """Read a units label (``m/s^2/N``, ``(1/N)*(m/s²)``, ``g/lbf``, ``µm/N``, ``in/s/lbf``, ...).

    Case is ignored; ``µ``/``μ`` is ``u``; superscripts (``²``, ``⁻¹``), ``^``,
    ``**`` and a digit right after a unit (``s2``) are exponents; ``*``,
    ``·`` or a blank multiply, ``/`` divides (left to right:
    ``m/s/N`` is ``(m/s)/N``), parentheses group.  Known units: :data:`KNOWN_UNITS`.

    Parameters
    ----------
    label : str
        The units label.

    Raises
    ------
    ValueError
        Saying what could not be read (an unknown unit name, a stray character).

    Examples
    --------
    >>> from mutext.uff import parse_units
    >>> u = parse_units("(1/N)*(m/s\\u00b2)")
    >>> u.quantity, u.reference, u.factor
    ('acceleration', 'force', 1.0)
    >>> u = parse_units("g/lbf")
    >>> u.quantity, round(u.factor, 6), u.definitions
    ('acceleration', 2.204623, ('g = 9.80665 m/s^2', 'lbf = 4.4482216152605 N'))
    """
    text = _normalise(label)
    pos, toks = 0, []
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None or m.end() == pos:
            rest = text[pos:].strip()
            if not rest:
                break
            raise ValueError(f"cannot read {rest[:1]!r} at {rest!r}")
        if m.group("atom"):
            name = m.group("atom")
            if name not in _ATOMS:
                raise ValueError(f"unknown unit {name!r}")
            toks.append(("atom", name))
            if m.group("exp"):
                toks.append(("op", "^" + m.group("exp")))
        elif m.group("one"):
            toks.append(("one", "1"))
        else:
            toks.append(("op", m.group("op")))
        pos = m.end()
    if not toks:
        raise ValueError("empty label")
    k = 0

    def factor():
        nonlocal k
        if k >= len(toks):
            raise ValueError("label ends where a unit is expected")
        kind, v = toks[k]
        k += 1
        if kind == "atom":
            fac, dims, d = _ATOMS[v]
            out = (fac, fac if dims[2] or dims[3] else 1.0, dims, (d,) if d else ())
        elif kind == "one":
            out = (1.0, 1.0, (0, 0, 0, 0), ())
        elif v == "(":
            out = expr()
            if k >= len(toks) or toks[k] != ("op", ")"):
                raise ValueError("unbalanced parentheses")
            k += 1
        else:
            raise ValueError(f"{v!r} where a unit is expected")
        while k < len(toks) and toks[k][0] == "op" and toks[k][1].startswith("^"):
            e = int(toks[k][1][1:])
            k += 1
            out = (out[0] ** e, out[1] ** e, tuple(e * x for x in out[2]), out[3])
        return out

    def expr():
        nonlocal k
        fac, rfac, dims, defs = factor()
        while k < len(toks) and toks[k] != ("op", ")"):
            kind, v = toks[k]
            sign = 1
            if kind == "op" and v in "*/":
                sign = -1 if v == "/" else 1
                k += 1
            f2, r2, d2, defs2 = factor()
            fac, rfac = fac * f2 ** sign, rfac * r2 ** sign
            dims = tuple(a + sign * b for a, b in zip(dims, d2))
            defs = defs + defs2
        return fac, rfac, dims, defs

    fac, rfac, dims, defs = expr()
    if k != len(toks):
        raise ValueError("unbalanced parentheses")
    return Units(str(label).strip(), float(fac), tuple(int(x) for x in dims), tuple(dict.fromkeys(defs)),
                 float(rfac))


def _label_used(text) -> bool:
    return text is not None and str(text).strip() != "" and str(text).strip().upper() != "NONE"


def relabel(label, units) -> str:
    """``label`` replaced by the user's mapping ``units`` ({label in the file: label to read}); keys match
    the label as written or ignoring case and blanks."""
    if not units or label is None:
        return label
    s = str(label).strip()
    if s in units:
        return units[s]
    key = re.sub(r"\s+", "", _normalise(s))
    for k, v in units.items():
        if re.sub(r"\s+", "", _normalise(k)) == key:
            return v
    return label


def motion_units(label) -> Units:
    """:func:`parse_units` for a motion (per force or current, or per nothing); ValueError if it is not."""
    u = parse_units(label)
    if u.quantity in (None, "?") or u.reference == "?":
        L, T, F, I = u.dims
        if L < 0 and (F > 0 or I > 0):
            raise ValueError("this is force per motion (dynamic stiffness, impedance or apparent mass); mutext "
                             "reads motion per force -- invert the data and the label")
        dims = " ".join(f"{n}^{e}" for n, e in zip(_DIMS, u.dims) if e) or "no dimension"
        raise ValueError(f"its dimension ({dims}) is not a displacement, velocity or acceleration "
                         f"(per force or current)")
    return u


def reference_units(label) -> Units:
    """:func:`parse_units` for a force or a current (a denominator); ValueError if it is not."""
    u = parse_units(label)
    L, T, F, I = u.dims
    if (L, T) != (0, 0) or (F, I) not in ((1, 0), (0, 1)):
        raise ValueError("not a force (N, kN, lbf, lb) or a current (A, mA)")
    return u


def units_hint(raw, example: str) -> str:
    """What to change, for an error about the units label ``raw``."""
    r = str(raw).strip()
    return (f"edit the label, or say how to read it: units={{{r!r}: {example!r}}} (mutext frf ... "
            f"--units '{r}={example}')")

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


def _norm_label(text) -> str | None:
    """An abscissa units label normalised for lookup (lower case, no blanks or parentheses), or None if unused."""
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
    units = units or {}
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
    notes = []
    if d.get("_latin1"):
        notes.append(f"header text not UTF-8 in {', '.join(d['_latin1'])}; read as Latin-1")
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
    num_lab, den_lab = relabel(raw_num, units), relabel(raw_den, units)
    example = _SI_LABEL.get(_RESPONSE_TYPES.get(rst), "m/s^2") + "/N"
    num = den = None
    if _label_used(num_lab):
        try:
            num = motion_units(num_lab)
        except ValueError as exc:
            raise _err(path, n, "ordinate_axis_units_lab",
                       f"unknown unit {str(raw_num).strip()!r} ({exc}); known: {KNOWN_UNITS}; "
                       f"{units_hint(raw_num, example)}") from None
    if _label_used(den_lab):
        try:
            den = reference_units(den_lab)
        except ValueError as exc:
            raise _err(path, n, "orddenom_axis_units_lab",
                       f"unknown unit {str(raw_den).strip()!r} ({exc}); known: N, kN, lbf, lb (force), A, mA "
                       f"(current); {units_hint(raw_den, 'N')}") from None
    quantity = in_q = None
    factor, defs = 1.0, ()
    if num is not None:
        quantity, factor, defs = num.quantity, num.factor, num.definitions
        in_q = num.reference
    if den is not None:
        den_q = "force" if den.dims[2] else "current"
        if in_q is not None:
            # the ordinate label holds the whole ratio: a denominator label must say the same
            if den_q != in_q or not math.isclose(num.reference_factor * den.factor, 1.0, rel_tol=1e-9):
                raise _err(path, n, "orddenom_axis_units_lab", f"units {str(raw_den).strip()!r} contradict the "
                                                               f"ordinate label {str(raw_num).strip()!r}")
        else:
            in_q, factor = den_q, factor / den.factor
            defs = tuple(dict.fromkeys(defs + den.definitions))
    sysname = "SI"
    length_f, force_f = 1.0, 1.0
    if u164 is not None:
        length_f, force_f = 1.0 / u164[0], 1.0 / u164[1]
        sysname = f"data set 164 units {u164[2] or '?'} (length x {length_f:g}, force x {force_f:g})"
    if quantity is None:
        if rst not in _RESPONSE_TYPES:
            raise _err(path, n, "ordinate_spec_data_type", f"unknown response quantity (specific data type {rst}) "
                                                           f"and no units label; cannot tell displacement, velocity "
                                                           f"or acceleration; {units_hint(raw_num, example)}")
        quantity, factor = _RESPONSE_TYPES[rst], factor * length_f
    elif rst in _RESPONSE_TYPES and _RESPONSE_TYPES[rst] != quantity:
        raise _err(path, n, "ordinate_spec_data_type", f"specific data type {rst} ({_RESPONSE_TYPES[rst]}) "
                                                       f"contradicts the units label {str(raw_num).strip()!r} "
                                                       f"({quantity})")
    if in_q is None:
        if dst not in _REFERENCE_TYPES:
            raise _err(path, n, "orddenom_spec_data_type", f"unknown reference quantity (specific data type {dst}) "
                                                           f"and no units label; label 'N' for a force, 'A' for a "
                                                           f"current")
        in_q, factor = "force", factor / force_f
    elif dst in _REFERENCE_TYPES and in_q != "force":
        raise _err(path, n, "orddenom_spec_data_type", f"specific data type {dst} (force) contradicts the "
                                                       f"reference units ({in_q})")
    # --- nodes and directions
    out_dir, s_out = _direction(path, n, "rsp_dir", d.get("rsp_dir"))
    in_dir, s_in = _direction(path, n, "ref_dir", d.get("ref_dir"))
    out_st = _station(path, n, "rsp_node", d.get("rsp_node"), mapping)
    in_st = _station(path, n, "ref_node", d.get("ref_node"), mapping)
    # --- conversion
    w = 2 * np.pi * f_hz
    G = data * factor
    in_unit = "N" if in_q == "force" else "A"
    steps = []
    file_units = (str(raw_num).strip() if num is not None else f"{_SI_LABEL[quantity]} [{sysname}]")
    if den is not None:
        file_units += f" / {str(raw_den).strip()}"
    if relabel(raw_num, units) != raw_num or relabel(raw_den, units) != raw_den:
        file_units += f", read as {(str(num_lab).strip() if num is not None else '')}" + \
            (f" / {str(den_lab).strip()}" if den is not None else "")
    if factor != 1.0:
        steps.append(f"scaled by {factor:.12g} to {_SI_LABEL[quantity]}/{in_unit}"
                     + (f" ({', '.join(defs)})" if defs else ""))
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
    if steps:
        meta["conversion"] = conv
    for k in ("id1", "id2", "id3", "id4", "id5", "rsp_ent_name", "ref_ent_name"):
        v = str(d.get(k, "") or "").strip()
        if v and v.upper() != "NONE":
            meta[f"uff_{k}"] = v
    if notes:
        meta["notes"] = notes
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


@validate_params({"ordinate": Options(("displacement", "velocity", "acceleration"))})
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

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np
    >>> from mutext.response import FRF
    >>> from mutext.uff import read_uff58, write_uff58
    >>> h = FRF(np.array([10.0, 20.0]), np.array([1e-3, 2e-3 + 1e-3j]), input_station=1, output_station=3)
    >>> with tempfile.TemporaryDirectory() as d:
    ...     back = read_uff58(write_uff58(os.path.join(d, "h.uff"), [h]))
    >>> len(back), back[0].label, bool(np.allclose(back[0].response, h.response))
    (1, 'F1->x3', True)
    """
    import pyuff
    path = Path(path)
    if isinstance(frfs, FRF):
        frfs = [frfs]
    frfs = list(frfs)
    if not frfs:
        raise ModelError(f"write_uff58 {path}: no FRF to write")
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
