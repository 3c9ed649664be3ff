"""What the integrity monitor keeps of each support (:class:`Watch`), what it finds
(:class:`Event`: an exclusion, a restoration, a receiver at fault) and what it decides each
cycle (:class:`Verdict`)."""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from ground_station.estimation.gnss_map import Change


@dataclass
class Watch:
    """What the monitor carries for one support between cycles."""

    covariance: np.ndarray | None = None  # of its estimate (its protection radius)
    reference: np.ndarray | None = None  # the motion test's: the last trusted fix, ...
    reference_covariance: np.ndarray | None = None
    predicted: np.ndarray | None = None  # ... carried by this cycle's commanded move
    excluded: bool = False
    recent: dict[str, deque[float]] = field(default_factory=dict)  # each test's statistics
    consistent: int = 0  # cycles in a row under the suspect gate, while excluded
    since: np.ndarray | None = None  # its estimate where it was excluded
    travel_m: float = 0.0  # how far its estimate went from there while excluded
    receiver: bool = False  # the bias followed it: its receiver's, not a place's
    taught: list[Change] = field(default_factory=list)  # what it taught G while excluded
    biased_at: np.ndarray | None = None  # its estimate at the last cycle with the bias seen
    quiet_at: np.ndarray | None = None  # ... at the first cycle it was gone
    biased_cycles: int = 0  # cycles it was seen since the exclusion
    motion_detectable_m: float | None = None  # its motion test's MDB this cycle
    fault_m: float = 0.0  # the undetected bias its estimate may carry (protection radius)
    protection_m: float | None = None  # its estimate's protection radius


@dataclass(frozen=True)
class Event:
    """An exclusion, a restoration, or a bias found to follow a support (its receiver's)."""

    support: str
    kind: str  # excluded, restored, receiver
    test: str = ""
    size_m: float = 0.0  # |nu| of the test that excluded it
    detectable_m: float = 0.0  # that test's minimal detectable bias (its worst direction)

    def record(self) -> dict:
        """What records.jsonl keeps of it."""
        found = {"support": self.support, "kind": self.kind}
        if self.kind == "excluded":
            found.update(
                test=self.test, size_m=round(self.size_m, 3), mdb_m=round(self.detectable_m, 3)
            )
        return found

    @property
    def text(self) -> str:
        """The STATUSTEXT the ground station sends."""
        if self.kind == "excluded":
            return f"Integrity: {self.support} excluded ({self.test} test, {self.size_m:.1f} m)"
        if self.kind == "receiver":
            return f"Integrity: {self.support} receiver at fault"
        return f"Integrity: {self.support} restored"


@dataclass(frozen=True)
class Verdict:
    """One cycle's outcome: each support's statistics, who is excluded, who is withheld from
    the fusion this cycle (the excluded, the suspect, the ambiguous), and what changed."""

    statistics: dict[str, dict[str, float]]
    excluded: frozenset[str]
    withheld: frozenset[str]
    ambiguous: tuple[str, ...]
    events: tuple[Event, ...]
    protection_m: dict[str, float | None] = field(default_factory=dict)  # work and supports

    def settled(self, found: Sequence[Event], protection: dict[str, float | None]) -> Verdict:
        """The verdict with what the cycle found after the fusion, and the estimates'
        protection radii."""
        return replace(self, events=self.events + tuple(found), protection_m=protection)

    def record(self) -> dict:
        """What records.jsonl keeps of it."""
        return {
            "statistics": {
                name: {test: round(value, 3) for test, value in tests.items()}
                for name, tests in self.statistics.items()
            },
            "excluded": sorted(self.excluded),
            "withheld": sorted(self.withheld),
            "ambiguous": list(self.ambiguous),
            "events": [event.record() for event in self.events],
            "protection_m": {
                name: None if radius is None else round(radius, 3)
                for name, radius in self.protection_m.items()
            },
        }
