"""Entry point for ``python -m vehicle_sim``."""

import sys

from mission.procs.math_threads import use_one_math_thread

use_one_math_thread()

from vehicle_sim.cli import entry_point  # noqa: E402  (numpy loads here, after the setting)

sys.exit(entry_point())
