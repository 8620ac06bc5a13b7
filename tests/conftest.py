"""Test-session settings: BLAS on one thread.

The matrices under test are small; on a 2-core CI machine a multi-threaded
BLAS only adds threads that spin against pytest and the solvers' own work.
"""
import numpy  # noqa: F401  (loads OpenBLAS first: threadpoolctl limits only libraries already loaded)
from threadpoolctl import threadpool_limits

_limits = threadpool_limits(limits=1, user_api="blas")


# ---------------------------------------------------------------------------
# parallel runs (pytest-xdist; pyproject's addopts: -n auto --dist loadfile)
# ---------------------------------------------------------------------------

import os  # noqa: E402

import pytest  # noqa: E402

# modules whose tests grade hostile submissions (litter in /tmp, /var/tmp, /dev/shm, shared memory, as
# root the unprivileged user) or check afterwards that those places are as they found them: one worker
# runs them all, so none of their children is alive during another's checks
_GRADING = ("test_grading_batch.py", "test_grading_hostile.py", "test_grading_reports.py",
            "test_grading_resources.py", "test_gradescope.py")


def _cpus() -> int:
    """The CPUs this process may use: its affinity mask, capped by a cgroup v2 CPU quota."""
    n = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    try:
        quota, period = open("/sys/fs/cgroup/cpu.max").read().split()
        if quota != "max":
            n = min(n, max(1, -(-int(quota) // int(period))))
    except (OSError, ValueError):
        pass
    return max(1, n)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_auto_num_workers(config):
    """``-n auto``: one worker per usable CPU, none (the tests run in this process) on a single CPU.
    PYTEST_XDIST_AUTO_NUM_WORKERS still decides when it is set."""
    env = os.environ.get("PYTEST_XDIST_AUTO_NUM_WORKERS")
    if env:
        return int(env)
    n = _cpus()
    return 0 if n == 1 else n


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """``--dist loadfile`` with one change: the grading modules of ``_GRADING`` are one unit, run by
    one worker.  A module stays one unit (its module-scoped fixtures are built once, its tests
    never race each other)."""
    if config.getvalue("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadFileScheduling

    class _Scheduling(LoadFileScheduling):
        def _split_scope(self, nodeid):
            module = super()._split_scope(nodeid)
            return "grading" if os.path.basename(module) in _GRADING else module

    return _Scheduling(config, log)
