"""Entry point for ``python -m vehicle_sim``."""

import sys

from vehicle_sim.cli import entry_point

sys.exit(entry_point())
