"""Hostile: write outside the child's directory: a .pth into site-packages (it would run in the
grader's process on every later grade), files in the grader's home, /tmp and the package.  The
payloads are inert comments; tests/test_grading_hostile.py checks that none of them exists."""
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

import pwd  # noqa: E402
import site  # noqa: E402
import sysconfig  # noqa: E402

MARK = "zz_mutext_hostile_marker"
_targets = [os.path.join(d, MARK + ".pth") for d in site.getsitepackages() + [sysconfig.get_paths()["purelib"]]]
_targets += [os.path.join(pwd.getpwuid(0).pw_dir, MARK), os.path.join(os.path.expanduser("~root"), MARK),
             os.path.join("/tmp", MARK), os.path.join("/var/tmp", MARK), os.path.join("/dev/shm", MARK),
             os.path.join(_grader_dir(), MARK + ".py")]
WRITTEN = []
for _t in _targets:
    try:
        with open(_t, "w") as _fh:
            _fh.write("# mutext hostile marker (inert)\n")
        WRITTEN.append(_t)
    except OSError:
        pass


def natural_frequency(t, y, cycles):
    # report how many writes succeeded: expected 0
    return float(len(WRITTEN))
