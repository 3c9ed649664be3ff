"""Entry point for ``python -m ground_station``."""

import sys

from mission.procs.math_threads import use_one_math_thread

use_one_math_thread()

from ground_station.cli import entry_point  # noqa: E402  (numpy loads here, after the setting)

sys.exit(entry_point())
