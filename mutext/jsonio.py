"""One JSON writer for the command line, the demos and the reports: numpy values and non-finite numbers.

JSON has no NaN or infinity; they are written as the strings ``"nan"``,
``"inf"`` and ``"-inf"`` (so that every ``--json`` output is strict JSON).
"""
from __future__ import annotations

import json
import math

import numpy as np

__all__ = ["to_json", "print_json", "plain"]


def plain(obj):
    """``obj`` with numpy arrays and scalars as lists and numbers, non-finite floats as strings.

    Parameters
    ----------
    obj : object
        Dicts, lists, tuples, numbers, strings, numpy arrays and scalars; complex
        numbers become ``[re, im]``, dict keys strings.
    """
    if isinstance(obj, dict):
        return {str(k): plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [plain(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return plain(obj.tolist())
    if isinstance(obj, (np.floating, np.integer, np.bool_)):
        return plain(obj.item())
    if isinstance(obj, complex):
        return [plain(obj.real), plain(obj.imag)]
    if isinstance(obj, float) and not math.isfinite(obj):
        return str(obj)
    return obj


def to_json(obj) -> str:
    """One-line strict JSON of ``obj`` (see :func:`plain`).

    Parameters
    ----------
    obj : object
        Dicts, lists, tuples, numbers, strings, numpy arrays and scalars (anything else as ``str``).

    Examples
    --------
    >>> import numpy as np
    >>> from mutext.jsonio import to_json
    >>> to_json({"f": np.array([1.5, np.inf]), "n": np.int64(3), "z": 1 + 2j})
    '{"f": [1.5, "inf"], "n": 3, "z": [1.0, 2.0]}'
    """
    return json.dumps(plain(obj), allow_nan=False, default=str)


def print_json(obj) -> None:
    """Print one JSON object (the ``--json`` output of the demos and commands).

    Parameters
    ----------
    obj : object
        As for :func:`to_json`.
    """
    print(to_json(obj))
