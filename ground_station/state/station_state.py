"""What the ground station carries from one control cycle to the next."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ground_station.state.assignment import Allocation


@dataclass
class StationState:
    """The estimates (xhat of the work UAV, yhat_n of each support), the current work waypoint
    k, the displacement each vehicle was last commanded, each support MPC's last path (its
    next warm start) and each support's role."""

    xhat: np.ndarray
    yhat: dict[str, np.ndarray]
    k: int
    last_work_command: np.ndarray = field(default_factory=lambda: np.zeros(3))
    last_support_command: dict[str, np.ndarray] = field(default_factory=dict)
    warm: dict[str, np.ndarray] = field(default_factory=dict)
    completed: bool = False
    blind_cycles: int = 0  # consecutive cycles with no estimate of the work UAV, up to now
    allocation: Allocation = field(default_factory=Allocation)  # each support's role

    def forget(self, support: str) -> None:
        """Drop what was carried for a support that fell silent and is back."""
        self.warm.pop(support, None)
        self.last_support_command.pop(support, None)
