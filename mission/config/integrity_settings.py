"""The ground station's integrity monitor: its tests' error rates, how long a fault
must persist to exclude a support and to restore it, and what an excluded support is given
(:mod:`ground_station.integrity`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from mission.config.checks import positive as _positive
from mission.config.checks import require as _require

MAX_CYCLES = 1000  # sustain and recovery: beyond this a fault is a run's whole length


@dataclass(frozen=True)
class IntegritySettings:
    """``enabled: false`` leaves the ground station as it was. Enabled, each cycle tests each
    support's GNSS fix against where its motion put it and against where the other supports'
    sightings put it, each a chi-square test with false-alarm rate ``false_alarm`` (per test,
    per cycle); a support whose tests exceed their gate for ``sustain_cycles`` cycles in a row
    (or whose statistics summed over them do) is excluded: not fused, navigated by the
    formation or dead reckoning, kept ``excluded_margin_m`` further from everything, and not
    teaching G a bias that follows it further than ``receiver_travel_m``. It is restored after
    ``recovery_cycles`` consistent cycles. ``missed_detection`` sets the minimal detectable
    bias the docs quote and is the protection radii's integrity risk: each estimate's error
    stays within its radius but with that probability, a receiver starting to lie in a cycle
    having probability ``fault_prior`` (its undetected bias counts only where that is the
    larger). ``motion_sigma_m`` (kinematic points) and
    ``motion_sigma_multicopter_m`` are the spread, per axis and cycle, of where a vehicle ends
    against where it was commanded."""

    enabled: bool
    false_alarm: float
    missed_detection: float
    sustain_cycles: int
    recovery_cycles: int
    motion_sigma_m: float
    motion_sigma_multicopter_m: float
    excluded_margin_m: float
    receiver_travel_m: float
    fault_prior: float

    def __post_init__(self) -> None:
        for name in ("false_alarm", "missed_detection", "fault_prior"):
            value = getattr(self, name)
            _require(0 < value < 0.5, name, f"must be a probability in (0, 0.5), got {value}")
        for name in ("sustain_cycles", "recovery_cycles"):
            value = getattr(self, name)
            _require(
                1 <= value <= MAX_CYCLES,
                name,
                f"must be a cycle count in 1..{MAX_CYCLES}, got {value}",
            )
        _positive(self, "motion_sigma_m", "motion_sigma_multicopter_m", "receiver_travel_m")
        _require(self.excluded_margin_m >= 0, "excluded_margin_m", "must not be negative")
        for name in (
            "motion_sigma_m",
            "motion_sigma_multicopter_m",
            "excluded_margin_m",
            "receiver_travel_m",
        ):
            _require(math.isfinite(getattr(self, name)), name, "must be finite")
