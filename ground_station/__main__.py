"""Entry point for ``python -m ground_station``."""

import sys

from ground_station.cli import entry_point

sys.exit(entry_point())
