"""Entry point for ``python -m mission``."""

import sys

from mission.cli import entry_point

sys.exit(entry_point())
