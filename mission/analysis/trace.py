"""What a ground station's tlog says about a run (:func:`mission.analysis.metrics.read_tlog`
reads it): the truth, the estimates, beliefs and setpoints, the cycles and the events."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mission.analysis.truth import interpolate


@dataclass
class RunTrace:
    """What a ground station's tlog says about a run, in simulated seconds."""

    truth: dict[tuple[int, float], np.ndarray] = field(default_factory=dict)
    # the true attitude with it (body FLU to world ENU, 3 x 3)
    attitudes: dict[tuple[int, float], np.ndarray] = field(default_factory=dict)
    estimates: dict[float, np.ndarray] = field(default_factory=dict)  # the work UAV's, by time
    # every vehicle's belief (LOCAL_POSITION_NED), setpoints and the estimates sent before them
    beliefs: dict[tuple[int, float], np.ndarray] = field(default_factory=dict)
    fixes: dict[tuple[int, float], np.ndarray] = field(default_factory=dict)  # 3-D GNSS fixes
    setpoints: dict[tuple[int, float], np.ndarray] = field(default_factory=dict)
    # the velocity a setpoint moves on at, where it has one (a flying vehicle's feed-forward)
    setpoint_velocities: dict[tuple[int, float], np.ndarray] = field(default_factory=dict)
    sent_estimates: dict[tuple[int, float], np.ndarray] = field(default_factory=dict)
    cycles: set[float] = field(default_factory=set)  # times of the work UAV's setpoints
    ticks: set[float] = field(default_factory=set)
    completion: float | None = None
    inspections_done: float | None = None  # "Inspections complete": every support's too
    link_events: list[dict[str, Any]] = field(default_factory=list)
    contacts: list[dict[str, Any]] = field(default_factory=list)  # as the vehicles reported them
    events: list[dict[str, Any]] = field(default_factory=list)  # faults, sets, failures
    stopped: str | None = None  # the ground station's word that it stopped the run
    max_gap_s: float = 1.0  # truth is interpolated between samples at most this far apart

    @property
    def supports(self) -> list[int]:
        """System ids of the support vehicles (the work UAV is system 1)."""
        return sorted({s for s, _ in self.truth if s != 1})

    @property
    def mode(self) -> str:
        """``lockstep`` (the ground station sent clock ticks) or ``realtime``."""
        return "lockstep" if self.ticks else "realtime"

    @property
    def cycle_times(self) -> list[float]:
        """The control cycles' times (one setpoint for the work UAV each)."""
        return sorted(self.cycles)

    def track(self, system: int) -> tuple[np.ndarray, np.ndarray]:
        """(times, positions) of one vehicle's truth."""
        times = sorted(t for s, t in self.truth if s == system)
        points = [self.truth[(system, t)] for t in times]
        return np.array(times), np.array(points).reshape(-1, 3)

    def truth_at(self, system: int, times: list[float]) -> tuple[np.ndarray, np.ndarray]:
        """One vehicle's truth at these times, and which of them are known."""
        track_times, positions = self.track(system)
        return interpolate(track_times, positions, np.array(times), self.max_gap_s)
