"""Units labels of measured FRFs (``m/s^2/N``, ``(1/N)*(m/s²)``, ``g/lbf`` ...) read as products of powers of
known units: the Universal File reader (:mod:`mutext.uff`) and the FRF file reader (:mod:`mutext.rig`) share it."""
from __future__ import annotations

import re
from dataclasses import dataclass

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
