"""Hostile: find the audit hook with gc, switch it off, put the real package first on sys.path, import."""
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
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(_grader_dir())), "instructor"))
for _name in [m for m in sys.modules if m == "mutext" or m.startswith("mutext.")]:
    del sys.modules[_name]
from mutext_grader.solutions.ex03_free_decay import *  # noqa: E402,F401,F403
