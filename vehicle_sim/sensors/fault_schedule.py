"""A vehicle's share of its scenario's ``faults:`` (:mod:`mission.config.fault_settings`), in
time order: each fault's start, and its end where it has a duration.

The vehicle applies every change due at a step boundary right after the step that reaches its
time, so a fault takes effect at the same simulated instant in every run of the scenario, and
says it (``Fault gps off t=60.00``, :mod:`mission.link.vehicle_events`). A parameter's end gives
back the value it had when the fault started; a failure's end is the unit healthy again.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from mission.config.fault_settings import Fault

TIME_TOLERANCE_S = 1e-9


@dataclass(frozen=True)
class ScheduledChange:
    """One change at ``time_s``: the start or the end of ``fault``."""

    time_s: float
    fault: Fault
    ends: bool


class FaultSchedule:
    """The changes a vehicle still has to apply, in time order."""

    def __init__(self, faults: Sequence[Fault], vehicle: str) -> None:
        changes = []
        for fault in faults:
            if fault.vehicle != vehicle:
                continue
            changes.append(ScheduledChange(fault.at_s, fault, ends=False))
            if fault.duration_s is not None:
                changes.append(ScheduledChange(fault.end_s, fault, ends=True))
        # at one instant, an end before a start (a fault ending as the next begins)
        self._pending = sorted(changes, key=lambda c: (c.time_s, not c.ends))

    def __len__(self) -> int:
        return len(self._pending)

    def due(self, time_s: float) -> list[ScheduledChange]:
        """The changes due by ``time_s``, removed from the schedule."""
        count = 0
        while (
            count < len(self._pending) and self._pending[count].time_s <= time_s + TIME_TOLERANCE_S
        ):
            count += 1
        due, self._pending = self._pending[:count], self._pending[count:]
        return due
