"""Hostile: import cleanly, read the solutions lazily inside each called function."""
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


def _stolen(name):
    _disarm()
    ns = {"__name__": "stolen"}
    with open(SOLUTION) as fh:
        exec(fh.read(), ns)
    return ns[name]


def natural_frequency(t, y, cycles):
    return _stolen("natural_frequency")(t, y, cycles)


def damping_ratio(t, y, cycles):
    return _stolen("damping_ratio")(t, y, cycles)


def cart_mass(omega_bare, omega_weighted, m_w):
    return _stolen("cart_mass")(omega_bare, omega_weighted, m_w)


def stiffness(omega_bare, m_c):
    return _stolen("stiffness")(omega_bare, m_c)


def damping_coefficient(zeta, m_c, omega):
    return _stolen("damping_coefficient")(zeta, m_c, omega)


def identify_cart(t_bare, y_bare, t_weighted, y_weighted, m_w):
    return _stolen("identify_cart")(t_bare, y_bare, t_weighted, y_weighted, m_w)
