"""Entry point for ``python -m mission``."""

import sys

from mission.procs.math_threads import use_one_math_thread

use_one_math_thread()  # numpy loads with one BLAS thread: `mission run` forks its vehicles

from mission.cli import entry_point  # noqa: E402

sys.exit(entry_point())
