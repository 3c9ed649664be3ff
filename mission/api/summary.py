"""A run's summary.json as typed Python: the figures a researcher reads most, and the rest as
the dictionary it is."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any


@dataclass(frozen=True)
class Spread:
    """Mean, 95th percentile and maximum of a run's values (None without values)."""

    mean: float | None
    p95: float | None
    max: float | None

    @classmethod
    def of(cls, data: dict[str, Any] | None) -> Spread:
        """From summary.json's ``{"mean": .., "p95": .., "max": ..}``."""
        data = data or {}
        return cls(data.get("mean"), data.get("p95"), data.get("max"))


@dataclass(frozen=True)
class Summary:
    """summary.json of a run. Every key is also reachable as ``summary["key"]``."""

    scenario: str
    method: str | None
    seed: int | None
    mode: str | None  # lockstep or realtime
    completed: bool
    completion_time_s: float | None  # simulated seconds; None where not completed
    stopped: str | None  # why the run was stopped (a crash), if it was
    control_cycles: int
    multipath_steps_total: int  # cycles a support's true position was in a zone
    multipath_steps: dict[str, int]
    work_error_m: Spread  # the work UAV's estimate against its truth, every cycle
    closest_approach_m: float | None  # of any two UAVs
    least_clearance_m: float | None  # of any UAV from the structure or the ground
    contacts: int  # vehicles that touched something (from the truth)
    decisions_digest: str | None
    wall_time_s: float | None
    raw: dict[str, Any] = field(repr=False, default_factory=dict)

    @classmethod
    def of(cls, data: dict[str, Any]) -> Summary:
        """From summary.json's object."""
        safety = data.get("safety") or {}
        return cls(
            scenario=data.get("scenario", ""),
            method=data.get("method"),
            seed=data.get("seed"),
            mode=data.get("mode"),
            completed=bool(data.get("completed")),
            completion_time_s=data.get("completion_time_s"),
            stopped=data.get("stopped"),
            control_cycles=int(data.get("control_cycles") or 0),
            multipath_steps_total=int(data.get("multipath_steps_total") or 0),
            multipath_steps=dict(data.get("multipath_steps") or {}),
            work_error_m=Spread.of(data.get("work_error_m")),
            closest_approach_m=safety.get("closest_approach_min_m"),
            least_clearance_m=safety.get("least_clearance_min_m"),
            contacts=int(safety.get("touching") or 0),
            decisions_digest=data.get("decisions_digest"),
            wall_time_s=data.get("wall_time_s"),
            raw=data,
        )

    def __getitem__(self, key: str) -> Any:
        return self.raw[key]

    def keys(self):
        """summary.json's keys."""
        return self.raw.keys()
