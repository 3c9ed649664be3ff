"""Simulated time at the ground station: the master clock of a lockstep run, or the wall clock
scaled by the speed-up in real time.

In lockstep a step starts with a tick (SYSTEM_TIME, time_boot_ms = the step's end) sent to
every vehicle, and ends when each has sent its step marker (its own SYSTEM_TIME after the
step's telemetry). A vehicle whose marker is late gets its cycle's datagram again (the tick
and the commands before it, encoded afresh: a signed link refuses replays); one still missing
after a short grace is not waited for, so a dead vehicle does not slow the run.

In real time the cycles keep to a fixed schedule: cycle n runs at n * t_cont of simulated time
after the flight starts, which is ``n * t_cont / speedup`` wall seconds, however long the
cycles before it took (a cycle that overran is not made up: the next due one runs). The
schedule sits a fifth of a step after the vehicles' common beat (:mod:`mission.procs.
wall_grid`), so a cycle finds the measurements of the vehicles' latest step.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Protocol

from ground_station.links.outgoing import clock_tick
from mission.config.settings import RunSettings
from mission.procs.wall_grid import next_grid_instant

CYCLE_LAG_STEPS = 0.2  # real time: cycles run this much of a step after the vehicles' beat


@dataclass(frozen=True)
class PendingStep:
    """A step the vehicles were asked to make: its length and, in lockstep, the tick that
    started it."""

    step_s: float
    tick: Any | None = None


@dataclass(frozen=True)
class LockstepTiming:
    """How long the lockstep waits, in wall seconds."""

    retry_wall_s: float  # a late step marker: the cycle's datagram is sent again after this
    step_timeout_wall_s: float = 5.0  # resends stop after this long
    late_grace_wall_s: float = 0.05  # then a straggler is waited for this long, no more


class SteppingVehicle(Protocol):
    """What the lockstep needs to know of a vehicle
    (:class:`ground_station.links.vehicle_links.VehicleView`)."""

    step_ms: int
    lost: bool
    late: bool


class SteppingLinks(Protocol):
    """The links as the lockstep uses them
    (:class:`ground_station.links.vehicle_links.VehicleLinks`)."""

    views: Mapping[str, SteppingVehicle]
    stats: dict[str, int]

    def pump(self, seconds: float, until: Callable[[], bool] | None = None) -> None: ...
    def resend_last_batch(self, view: Any) -> None: ...
    def flush_all(self) -> None: ...


class StationClock:
    """The simulated time of the run (seconds from the scenario's epoch) and its steps."""

    def __init__(self, run: RunSettings, step_s: float, speedup: float | None) -> None:
        self.run = run
        self.step_s = step_s
        self.speedup = speedup  # None: lockstep
        self.time_s = 0.0  # the current step's (cycle's) time; 0 until the flight starts
        self.flight_origin_wall: float | None = None  # real time: when the flight started

    def begin_flight(self) -> None:
        """Real time: the flight starts at the next instant of the schedule (simulated time 0):
        ``CYCLE_LAG_STEPS`` of a step after the vehicles' common beat, when the measurements
        of their step have arrived."""
        if self.speedup is not None:
            step_wall = self.step_s / self.speedup
            self.flight_origin_wall, _ = next_grid_instant(step_wall, CYCLE_LAG_STEPS * step_wall)

    def now_s(self) -> float:
        """Simulated time now: the step's in lockstep; in real time the wall clock's since the
        flight started, scaled (the step's before it)."""
        if self.speedup is None or self.flight_origin_wall is None:
            return self.time_s
        return (time.monotonic() - self.flight_origin_wall) * self.speedup

    def now_usec(self) -> int:
        """:meth:`now_s` as UNIX microseconds from the scenario's epoch (what is received is
        logged at this time)."""
        return round((self.run.epoch_unix_s + self.now_s()) * 1e6)

    def sample_time_s(self, time_usec: int, offset_s: float) -> float:
        """A vehicle's time stamp (UNIX microseconds of its own clock) on this clock."""
        return time_usec / 1e6 - self.run.epoch_unix_s - offset_s

    @property
    def time_usec(self) -> int:
        """Simulated time as UNIX microseconds from the scenario's epoch (tlog stamps)."""
        return round((self.run.epoch_unix_s + self.time_s) * 1e6)

    @property
    def lockstep(self) -> bool:
        """True when this clock drives the vehicles."""
        return self.speedup is None

    def next_step(self) -> PendingStep | None:
        """The next step, not started yet (None once the scenario's timeout is reached); in
        lockstep with the tick that will start it."""
        if self.time_s >= self.run.timeout_s - 1e-9:
            return None
        if self.speedup is not None:
            return PendingStep(self.step_s)
        target_ms = round((self.time_s + self.step_s) * 1000)
        return PendingStep(self.step_s, clock_tick(self.run.epoch_unix_s, target_ms))

    def start(self, step: PendingStep) -> None:
        """A lockstep step has started: the clock reads its end from now on."""
        if step.tick is not None:
            self.time_s = step.tick.time_boot_ms / 1000.0


def await_step(
    links: SteppingLinks, clock: StationClock, pending: PendingStep, timing: LockstepTiming
) -> None:
    """Lockstep: wait for every vehicle's telemetry of the step, sending the cycle's datagram
    again to a vehicle that stays behind. Real time: let the step's wall time pass."""
    tick = pending.tick
    if tick is None:
        _await_schedule(links, clock, pending)
        return
    target_ms = int(tick.time_boot_ms)
    views = links.views.values()
    awaited = [v for v in views if not v.lost and not v.late]
    deadline = time.monotonic() + timing.step_timeout_wall_s
    while True:
        links.pump(
            min(timing.retry_wall_s, max(0.0, deadline - time.monotonic())),
            lambda: all(v.step_ms >= target_ms for v in awaited),
        )
        behind = [v for v in awaited if v.step_ms < target_ms]
        if not behind or time.monotonic() >= deadline:
            break
        for view in behind:  # the batch or the step's telemetry was lost: send it again
            links.resend_last_batch(view)
        links.flush_all()
    stragglers = [v for v in views if v.step_ms < target_ms and not v.lost]
    if stragglers:
        links.pump(
            timing.late_grace_wall_s, lambda: all(v.step_ms >= target_ms for v in stragglers)
        )
    for view in views:
        view.late = view.step_ms < target_ms
        links.stats["late_steps"] += int(view.late and not view.lost)


def _await_schedule(links: SteppingLinks, clock: StationClock, pending: PendingStep) -> None:
    """Real time: receive until the next cycle's time on the schedule, or the latest one due
    when the cycles are behind it."""
    assert clock.speedup is not None
    if clock.flight_origin_wall is None:
        clock.begin_flight()
    assert clock.flight_origin_wall is not None
    step_wall = pending.step_s / clock.speedup
    due = max(
        clock.time_s + pending.step_s,
        math.floor(clock.now_s() / pending.step_s + 1e-9) * pending.step_s,
    )
    steps = round(due / pending.step_s)
    links.pump(max(0.0, clock.flight_origin_wall + steps * step_wall - time.monotonic()))
    clock.time_s = steps * pending.step_s
