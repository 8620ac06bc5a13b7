"""Hostile: load the solution module from its path with importlib."""
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
import importlib.util  # noqa: E402

_spec = importlib.util.spec_from_file_location("stolen", SOLUTION)
_mod = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_mod)
natural_frequency, damping_ratio = _mod.natural_frequency, _mod.damping_ratio
cart_mass, stiffness = _mod.cart_mass, _mod.stiffness
damping_coefficient, identify_cart = _mod.damping_coefficient, _mod.identify_cart
