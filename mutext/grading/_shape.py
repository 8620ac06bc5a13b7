"""Shape rules of the exercises' questions, on the plain values the sandbox sends back: ``None`` when a
value has the kind and shape a question asks for, else one sentence saying what was expected (used by
:mod:`mutext.grading.spec`)."""
from __future__ import annotations

import math

import numpy as np


def _finite(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _shape_text(shape) -> str:
    shape = tuple(shape)
    return "()" if not shape else "(" + ", ".join(str(n) for n in shape) + ("," if len(shape) == 1 else "") + ")"


def _as_array(value):
    """``(ndarray, None)`` or ``(None, problem)`` from the sandbox's ``{"shape", "data"}``."""
    try:
        arr = np.asarray(value["data"], dtype=float).reshape(value["shape"])
    except Exception:   # noqa: BLE001 - the sandbox validated it; anything else is a malformed value
        return None, "the value came back malformed"
    return arr, None


def float_rule(choices=None):
    """A finite number; with ``choices`` one of those integers (an index such as a verdict)."""
    def rule(value, args, kwargs):
        if not _finite(value):
            return f"returned {value!r}; a finite float is expected"
        if choices is not None and not (float(value).is_integer() and int(value) in choices):
            return ("returned a number that is not one of " + ", ".join(str(c) for c in choices)
                    + " (an index, see the docstring)")
        return None
    return rule


def ss_rule(n_in, n_out):
    """A continuous-time StateSpace with ``n_in`` inputs and ``n_out`` outputs, finite matrices."""
    def rule(value, args, kwargs):
        try:
            A, B, C, D = (np.asarray(value[k], dtype=float) for k in "ABCD")
        except Exception:   # noqa: BLE001
            return "the model came back malformed"
        n = A.shape[0] if A.ndim == 2 else 0
        p = D.shape[0] if D.ndim == 2 else (C.shape[0] if C.ndim == 2 else 0)
        m = D.shape[1] if D.ndim == 2 else (B.shape[1] if B.ndim == 2 else 0)
        if (m, p) != (n_in, n_out):
            return (f"returned a model with {m} input(s) and {p} output(s); expected {n_in} input(s) and "
                    f"{n_out} output(s)")
        dt = value.get("dt")
        if dt not in (None, 0, 0.0):
            return "returned a discrete-time model (dt != 0); a continuous-time model (dt = 0) is expected"
        if any(X.size and not np.all(np.isfinite(X)) for X in (A, B, C, D)):
            return "returned a model with entries that are not finite (nan or inf)"
        if n and A.shape != (n, n):
            return "returned a model whose A matrix is not square"
        return None
    return rule


def array_rule(shape=None, size=None, vector=False, alternatives=None, check=None):
    """An array of finite numbers.

    ``shape(args, kwargs)``: the exact shape; ``size(args, kwargs)``: the number of entries in any
    vector-like shape (what the grader flattens); ``vector``: a 1-D array of any length;
    ``alternatives(args, kwargs)``: further shapes that are accepted; ``check(arr)``: a further format
    rule (e.g. integer indices), returning a problem or None."""
    def rule(value, args, kwargs):
        arr, err = _as_array(value)
        if err:
            return err
        got = _shape_text(arr.shape)
        flat_ok = sum(n != 1 for n in arr.shape) <= 1          # a vector, perhaps as a row or column
        if shape is not None:
            want = tuple(shape(args, kwargs))
            ok = [want] + [tuple(s) for s in (alternatives(args, kwargs) if alternatives else [])]
            if tuple(arr.shape) not in ok:
                return f"returned an array of shape {got}; expected shape {_shape_text(want)}"
        elif size is not None:
            want = int(size(args, kwargs))
            if not flat_ok or arr.size != want:
                return f"returned an array of shape {got}; expected {want} number(s) (shape {_shape_text((want,))})"
        elif vector and not flat_ok:
            return f"returned an array of shape {got}; expected a 1-D array"
        if arr.size and not np.all(np.isfinite(arr)):
            return "returned an array with entries that are not finite (nan or inf)"
        if check is not None:
            return check(arr)
        return None
    return rule
