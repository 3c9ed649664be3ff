"""A vehicle's share of its scenario's ``faults:`` (:mod:`mission.config.fault_settings`), in
time order: each fault's start, and its end where it has a duration.

The vehicle applies every change due at a step boundary right after the step that reaches its
time, so a fault takes effect at the same simulated instant in every run of the scenario, and
says it (``Fault gps off t=60.00``, :mod:`mission.link.vehicle_events`). A parameter's end gives
back the value it had when the fault started; a failure's end is the unit healthy again.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from mission.config.fault_settings import Fault
from vehicle_sim.mavlink.parameters import ParameterTable
from vehicle_sim.sensors import failures

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


class FaultInjector:
    """Applies a vehicle's scheduled faults as they come due: a failure through the vehicle's
    failure injection, a parameter set in its table and passed to the vehicle's hook for a
    change, both said as ``Fault``."""

    def __init__(
        self,
        schedule: FaultSchedule,
        parameters: ParameterTable,
        inject_failure: Callable[[int, int, str], bool],
        parameter_set: Callable[[str, float, str], None],
    ) -> None:
        self.schedule = schedule
        self._parameters = parameters
        self._inject_failure = inject_failure
        self._parameter_set = parameter_set
        self._before_fault: dict[int, float] = {}  # a parameter's value before its fault

    def apply_due(self, time_s: float) -> None:
        """Every change due by ``time_s`` (at a step boundary)."""
        if not len(self.schedule):
            return
        for change in self.schedule.due(time_s):
            fault = change.fault
            if fault.failure is not None:
                unit, kind = failures.parse_failure(fault.failure)
                self._inject_failure(unit, failures.OK if change.ends else kind, "Fault")
                continue
            table = self._parameters
            index = table.index_of(str(fault.param))
            assert index is not None  # the scenario's check: a catalogue id
            if change.ends:
                value = self._before_fault.pop(index)
            else:
                self._before_fault[index] = table[index].value
                value = float(fault.value)  # type: ignore[arg-type]
            table.set(index, value)
            self._parameter_set(table[index].name, value, "Fault")
