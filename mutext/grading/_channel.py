"""The results channel: the child's event lines read from the results file, and every value it sends
back checked to be plain data of the promised shape within the size limits."""
from __future__ import annotations

import json
import math
import tempfile

from ._rules import _real
from ._settings import MAX_ELEMENTS, MAX_STATES


class _Events:
    """Reads complete lines appended to the results file, keeping those with our nonce.

    Lines are decoded defensively: only JSON objects (plain data) are kept,
    malformed or absurdly nested lines are dropped, and so is a line longer
    than :attr:`MAX_LINE` bytes, unread (the parent reads at most that much
    of it at a time, not the whole line)."""

    MAX_LINE = 16 * 2 ** 20

    def __init__(self, path, nonce):
        self.path, self.nonce, self.pos = path, nonce, 0
        self.skipping = False     # inside a line that is too long: drop everything up to its end

    def read(self):
        try:
            with open(self.path, "rb") as fh:
                fh.seek(self.pos)
                data = fh.read(self.MAX_LINE + 1)
        except FileNotFoundError:
            return []
        out = []
        while data:
            end = data.find(b"\n") if self.skipping else data.rfind(b"\n")
            if self.skipping:
                if end < 0:
                    self.pos += len(data)
                    return out
                self.pos += end + 1
                data = data[end + 1:]
                self.skipping = False
                continue
            if end < 0:
                if len(data) > self.MAX_LINE:
                    self.pos += len(data)
                    self.skipping = True
                return out
            self.pos += end + 1
            for line in data[:end].splitlines():
                if len(line) > self.MAX_LINE:
                    continue
                try:
                    ev = json.loads(line)
                except Exception:   # noqa: BLE001 - ValueError, RecursionError: not ours
                    continue
                if isinstance(ev, dict) and ev.get("nonce") == self.nonce:
                    out.append(ev)
            return out
        return out


def _number(x):
    return (isinstance(x, float) or (isinstance(x, int) and not isinstance(x, bool) and abs(x) <= 2 ** 63))


def _size(n, cap=MAX_STATES):
    return isinstance(n, int) and not isinstance(n, bool) and 0 <= n <= cap


def _matrix(m, rows, cols):
    """``m`` is a list of ``rows`` lists of ``cols`` numbers (``cols`` None: any one length)."""
    if not (isinstance(m, list) and len(m) == rows and all(isinstance(r, list) for r in m)):
        return False
    if rows and cols is None:
        cols = len(m[0])
    return all(len(r) == cols for r in m) and all(_number(v) for r in m for v in r)


def _valid_value(kind, v):
    """A value sent by the child has the plain shape its kind promises, within the size limits
    (:data:`MAX_STATES`, :data:`MAX_ELEMENTS`): sizes are checked before any number is looked at."""
    if kind == "float":
        return _number(v)
    if kind == "array":
        if not (isinstance(v, dict) and isinstance(v.get("shape"), list) and isinstance(v.get("data"), list)):
            return False
        shape = v["shape"]
        return (len(shape) <= 32 and all(_size(n, MAX_ELEMENTS) for n in shape)
                and math.prod(shape) == len(v["data"]) <= MAX_ELEMENTS and all(_number(x) for x in v["data"]))
    if kind == "ss":
        if not (isinstance(v, dict) and all(isinstance(v.get(k), list) for k in "ABCD")):
            return False
        A, B, C, D = (v[k] for k in "ABCD")
        n, p = len(A), len(D)
        m = len(D[0]) if p and isinstance(D[0], list) else (len(B[0]) if n and isinstance(B[0], list) else 0)
        if not (_size(n) and _size(p) and _size(m) and len(C) == p and (n or not B)
                and n * n + n * m + p * n + p * m <= MAX_ELEMENTS):
            return False
        if not (_matrix(A, n, n) and _matrix(B, n, m) and _matrix(C, p, n) and _matrix(D, p, m)):
            return False
        return ((v.get("dt") is None or _number(v.get("dt")))
                and all(isinstance(v.get(k, []), list) and len(v.get(k, [])) <= MAX_STATES
                        and all(isinstance(x, str) and len(x) <= 200 for x in v.get(k, []))
                        for k in ("inputs", "outputs")))
    return False


def _clean_calls(kind, calls, n):
    """The child's list of call outcomes, checked: ``{"ok": True, "value": ...}`` or ``{"ok": False, "error": str}``."""
    out = []
    for c in (calls if isinstance(calls, list) else [])[:n]:
        if isinstance(c, dict) and c.get("ok") is True and _valid_value(kind, c.get("value")):
            out.append({"ok": True, "value": c["value"]})
        elif isinstance(c, dict) and c.get("ok") is False and isinstance(c.get("error"), str):
            out.append({"ok": False, "error": c["error"][:2000]})
        else:
            out.append({"ok": False, "error": "the grading process sent back a malformed value"})
    return out


def _confinement(ev, mode, batch=()):
    """``(isolation, details)`` from the child's ``confined`` event (``batch``: the submission's original
    file and its batch-mates, which the child's probe tried to read too)."""
    applied = [str(a) for a in ev.get("applied") or []][:20]
    problems = [str(a)[:300] for a in ev.get("problems") or []][:20]
    found = [str(a) for a in ev.get("readable") or []][:200]
    readable = [a for a in found if a not in batch][:10]
    mates = [a for a in found if a in batch][:5]
    writable = [str(a) for a in ev.get("writable") or []][:10]
    details = applied + problems
    tmp = _real(tempfile.gettempdir())
    critical = [w for w in writable if w != tmp]
    if readable:
        details.append("the submission could read " + ", ".join(readable))
    if mates:
        details.append("the submission could read the files of its directory (its own original, other "
                       "submissions): " + ", ".join(mates))
        readable += mates
    if writable:
        details.append("the submission could write into " + ", ".join(writable))
    if readable or critical:
        return "none", details
    if mode == "root" and any(a.startswith("uid ") for a in applied):
        return "uid", details
    if any(a.startswith("landlock") for a in applied):
        return "landlock", details
    return "none", details

