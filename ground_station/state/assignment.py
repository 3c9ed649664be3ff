"""Who does what now: each support's role and its progress through its inspection (the state
the task allocation, :mod:`ground_station.roles.allocation`, carries from cycle to cycle)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

FORMATION, INSPECTING, RETURNING = "formation", "inspecting", "returning"


@dataclass
class SupportRole:
    """One support's role, its next inspection waypoint, the corners left on its route and how
    long it has been giving way."""

    role: str = FORMATION
    next_inspection: int = 0
    route: np.ndarray | None = None
    held: int = 0  # cycles it gave way since its route was planned


@dataclass
class Allocation:
    """Every support's role; how many times a role changed; the last look ahead (s)."""

    supports: dict[str, SupportRole] = field(default_factory=dict)
    switches: int = 0
    clear_s: float | None = None

    def role(self, name: str) -> str:
        """The support's role (formation unless set)."""
        return self.supports.get(name, SupportRole()).role

    def members(self, names: list[str]) -> list[str]:
        """The supports of ``names`` in the formation."""
        return [n for n in names if self.role(n) == FORMATION]

    def record(self) -> dict[str, object]:
        """What a cycle's record carries: roles, inspection progress, the look ahead."""
        return {
            "roles": {n: r.role for n, r in sorted(self.supports.items())},
            "next_inspection": {n: r.next_inspection for n, r in sorted(self.supports.items())},
            "clear_s": None
            if self.clear_s is None
            else (None if math.isinf(self.clear_s) else round(self.clear_s, 2)),
        }
