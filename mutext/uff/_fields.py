"""The fields of a data set 58: codes of its types and directions, and how a field is read (an error names
the file, the data set and the field)."""
from __future__ import annotations

import math
import re

from ..response import FRFFileError

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


def _mutext_tokens(line) -> dict:
    """``key=value`` tokens of an ID line written by :func:`mutext.uff.write_uff58` (``mutext key=value ...``)."""
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

