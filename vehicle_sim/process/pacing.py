"""When a vehicle steps (BlueSky's split between simulation and pacing):

- lockstep: the ground station is the master clock. A SYSTEM_TIME from it (time_boot_ms = T)
  means "advance to T"; a vehicle started into a running mission takes up the clock from its
  first tick. With no tick for ``lockstep_timeout_wall_s`` the vehicle advances one
  step alone, so a lost packet cannot freeze it; before the first tick it only sends heartbeats.
- real time: one step every ``t_cont / speedup`` wall seconds, on the host's common beat
  (:mod:`mission.procs.wall_grid`: every vehicle samples at the same instants); the vehicle's
  simulated clock is its own (it counts from its start, as an autopilot's time since boot),
  and it answers TIMESYNC with it so the ground station can map its stamps onto its clock.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

from mission.procs.wall_grid import next_grid_instant
from vehicle_sim.dynamics.clock import StepClock

IDLE_HEARTBEAT_WALL_S = 1.0
MAX_TICK_JUMP_S = 60.0  # a clock tick may advance at most this far (guards against garbage)
MAX_JOIN_S = 1e6  # s: a run joined later than 11 days in is no run (2^32 ms is 49 days)
TIME_TOLERANCE_S = 1e-9


@dataclass(frozen=True)
class ClockSettings:
    """How simulated time advances."""

    lockstep: bool
    speedup: float = 1.0


class Pacing:
    """When the steps of a vehicle's ``clock`` are due, and the physical instant of each (the
    truth channel's time)."""

    def __init__(
        self, settings: ClockSettings, clock: StepClock, lockstep_timeout_wall_s: float
    ) -> None:
        self.settings = settings
        self.clock = clock
        self.lockstep_timeout_wall_s = lockstep_timeout_wall_s
        self.started = False  # lockstep: a tick has come
        self.requested_s = 0.0  # lockstep: the simulated time the ticks ask for
        self.last_tick_wall = 0.0
        self.last_idle_heartbeat = -math.inf
        self.origin_wall = 0.0
        self.origin_unix = 0.0  # the same instant on the host's wall clock (truth channel)

    @property
    def step_wall_s(self) -> float:
        """A step's wall time in real time."""
        return self.clock.step_s / self.settings.speedup

    def start(self) -> None:
        """Now (real time: the host's next common beat) is the clock's origin."""
        self.origin_wall, self.origin_unix = time.monotonic(), time.time()
        if not self.settings.lockstep:  # steps on the host's common beat (sensors on a PPS)
            self.origin_wall, self.origin_unix = next_grid_instant(self.step_wall_s)

    def next_deadline(self, now: float) -> float:
        """When something is next due: a step, a lone step, an idle heartbeat."""
        clock = self.clock
        if self.settings.lockstep:
            if self.started and self.requested_s > clock.sim_time_s + TIME_TOLERANCE_S:
                return now
            if self.started:
                return self.last_tick_wall + self.lockstep_timeout_wall_s
            return self.last_idle_heartbeat + IDLE_HEARTBEAT_WALL_S
        return self.origin_wall + (clock.steps + 1) * self.step_wall_s

    def may_join(self, time_s: float) -> bool:
        """Whether a tick for ``time_s`` finds a vehicle (re)started into a running mission."""
        clock = self.clock
        return not self.started and clock.steps == 0 and time_s > clock.step_s + TIME_TOLERANCE_S

    def request(self, time_s: float, now: float) -> bool:
        """A tick asks for ``time_s``; False if it is no step forward or too far ahead."""
        if not 0 < time_s - self.clock.sim_time_s <= MAX_TICK_JUMP_S:
            return False
        self.requested_s = max(self.requested_s, time_s)
        self.started = True
        self.last_tick_wall = now
        return True

    def lone_step(self, now: float) -> bool:
        """Lockstep: with no tick for the timeout, ask for one step alone (True if so)."""
        clock = self.clock
        if not (self.settings.lockstep and self.started):
            return False
        idle = self.requested_s <= clock.sim_time_s + TIME_TOLERANCE_S
        if idle and now - self.last_tick_wall > self.lockstep_timeout_wall_s:
            self.requested_s = clock.sim_time_s + clock.step_s
            self.last_tick_wall = now
            return True
        return False

    def step_due(self, now: float) -> bool:
        """Whether the clock's next step is due."""
        clock = self.clock
        if self.settings.lockstep:
            return self.started and self.requested_s > clock.sim_time_s + TIME_TOLERANCE_S
        elapsed = (now - self.origin_wall) * self.settings.speedup
        return clock.steps < math.floor(elapsed / clock.step_s + TIME_TOLERANCE_S)

    def idle_heartbeat_due(self, now: float) -> bool:
        """Lockstep before the first tick: whether a heartbeat is due (noted as sent)."""
        if self.settings.lockstep and not self.started:
            due = now - self.last_idle_heartbeat >= IDLE_HEARTBEAT_WALL_S
            if due:
                self.last_idle_heartbeat = now
            return due
        return False

    def physical_usec(self, steps_back: int = 0) -> int:
        """The physical time of the current step (or of one ``steps_back`` before it) for the
        truth channel: simulated time in lockstep, the host's wall clock at the step's nominal
        instant in real time."""
        steps = self.clock.steps - steps_back
        if self.settings.lockstep:
            return round(steps * self.clock.step_s * 1e6)
        return round((self.origin_unix + steps * self.step_wall_s) * 1e6)

    def truth_wait_wall_s(self, timeout_wall_s: float) -> float:
        """How long a support waits for the work UAV's truth of its step: the timeout, in real
        time at most one step's wall time."""
        if self.settings.lockstep:
            return timeout_wall_s
        return min(timeout_wall_s, self.step_wall_s)

    def simulated_ns(self, now: float) -> int:
        """Real time: the vehicle's clock at wall instant ``now`` (not the last step's time)."""
        return round((now - self.origin_wall) * self.settings.speedup * 1e9)
