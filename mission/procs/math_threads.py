"""One BLAS thread per process, set before numpy loads.

Every simulated vehicle, the ground station and its MPC helper are separate processes doing
3x3 to 15x15 linear algebra, too small for BLAS to split. A multi-threaded BLAS (numpy's
OpenBLAS starts one worker per core) then only competes with the other processes for the
cores: its start-up alone costs each process ~60 ms of CPU, and a mission's wall time was
~5 % longer with it. A value the user has set is kept.
"""

from __future__ import annotations

import os

THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def use_one_math_thread() -> None:
    """Ask BLAS for one thread unless the environment already says how many (call this
    before anything imports numpy)."""
    for name in THREAD_VARIABLES:
        os.environ.setdefault(name, "1")
