"""Test-session settings: BLAS on one thread.

The matrices under test are small; on a 2-core CI machine a multi-threaded
BLAS only adds threads that spin against pytest and the solvers' own work.
"""
import numpy  # noqa: F401  (loads OpenBLAS first: threadpoolctl limits only libraries already loaded)
from threadpoolctl import threadpool_limits

_limits = threadpool_limits(limits=1, user_api="blas")
