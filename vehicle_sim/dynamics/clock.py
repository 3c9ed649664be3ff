"""A vehicle's simulated clock: whole steps since its start (an autopilot's time since boot),
and the same instant as UNIX time from the scenario's epoch."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass
class StepClock:
    """The simulated time of a vehicle that steps ``step_s`` at a time."""

    step_s: float
    epoch_unix_s: float
    steps: int = 0

    @property
    def sim_time_s(self) -> float:
        """Simulated seconds since start."""
        return self.steps * self.step_s

    @property
    def time_boot_ms(self) -> int:
        """Simulated milliseconds since start."""
        return round(self.sim_time_s * 1000)

    @property
    def time_unix_usec(self) -> int:
        """Simulated time as UNIX microseconds from the scenario's epoch."""
        return round((self.epoch_unix_s + self.sim_time_s) * 1e6)

    def advance(self) -> None:
        """One step on."""
        self.steps += 1

    def join(self, time_s: float) -> None:
        """Take up a running clock before the first step: the next step ends at ``time_s``."""
        self.steps = max(0, round(time_s / self.step_s) - 1)
