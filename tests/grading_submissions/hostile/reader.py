"""Not an exercise submission: functions that tests/test_grading_resources.py calls through
``run_submission`` to check the child from the inside (the audit hook is switched off first).

``read_paths(paths)``: 1 for each path the child could read, else 0 (solutions reached through a
symbolic link, a batch-mate's file).  ``litter(tag)``: leaves files and a directory tree in /tmp,
/var/tmp and /dev/shm, returns how many it could create.  ``stall()``: never returns."""
import gc
import os
import time

MARK = "zz_mutext_hostile_litter"


def _disarm():
    for o in gc.get_objects():
        if type(o).__name__ == "Guard":
            o.blocked, o.modules, o.phase, o.protected = [], (), None, "/nonexistent"
            o._local.busy = True


def read_paths(paths):
    _disarm()
    out = []
    for p in paths:
        try:
            with open(p, "rb") as fh:
                fh.read(1)
            out.append(1.0)
        except OSError:
            out.append(0.0)
    return out


def litter(tag):
    _disarm()
    made = 0
    for d in ("/tmp", "/var/tmp", "/dev/shm"):
        try:
            with open(os.path.join(d, f"{MARK}_{tag}"), "wb") as fh:
                fh.write(b"x" * 2 ** 20)
            made += 1
            top = os.path.join(d, f"{MARK}_{tag}_tree")
            os.makedirs(os.path.join(top, "a", "b", "c"))
            os.chmod(os.path.join(top, "a"), 0)
            made += 1
        except OSError:
            pass
    return [float(made)]


def stall():
    while True:
        time.sleep(1)
