"""A tlog read through pymavlink's own tolerant reader (every message decoded): the reference
the project's fast reader (:func:`mission.analysis.metrics.read_tlog`) is tested against."""

from __future__ import annotations

from pathlib import Path

from mission.analysis.metrics import pymavlink_messages, trace_of_messages
from mission.analysis.trace import RunTrace
from mission.config.settings import Scenario


def read_tlog_with_mavutil(tlog: Path, scenario: Scenario) -> RunTrace:
    """The trace :func:`mission.analysis.metrics.read_tlog` gives, through pymavlink."""
    return trace_of_messages(pymavlink_messages(tlog), scenario)
