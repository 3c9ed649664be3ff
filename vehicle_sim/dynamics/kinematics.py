"""Vehicle motion as a kinematic point (docs/vehicle.md, "Navigation"): the autopilot steers
toward its target from the position it *believes*, so an estimate error moves the true vehicle
wrongly."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Kinematics:
    """True and believed position of one multicopter, and its position target (ENU, m)."""

    truth: np.ndarray
    believed: np.ndarray
    target: np.ndarray | None = None
    target_velocity: np.ndarray | None = None  # a setpoint's velocity: the target moves on
    velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))
    path: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # the last step's ends

    @classmethod
    def at(cls, home: np.ndarray) -> Kinematics:
        """A vehicle hovering at ``home`` that knows where it is."""
        home = np.asarray(home, dtype=float).reshape(3)
        return cls(truth=home.copy(), believed=home.copy())

    def set_estimate(self, estimate: np.ndarray) -> None:
        """The navigation estimate streamed by the ground station replaces the believed position."""
        self.believed = np.asarray(estimate, dtype=float).reshape(3).copy()

    def hold(self) -> None:
        """Hold where the autopilot believes it is."""
        self.target = self.believed.copy()
        self.target_velocity = None

    def stop_at(self, position: np.ndarray) -> None:
        """Stopped dead at ``position`` (a crash): truth and belief there, no target."""
        self.truth = np.asarray(position, dtype=float).reshape(3).copy()
        self.believed = self.truth.copy()
        self.target = None
        self.target_velocity = None
        self.velocity = np.zeros(3)

    def step(
        self, dt_s: float, speed_limit_m_s: float, rng: np.random.Generator, noise_m: float
    ) -> np.ndarray:
        """Advance ``dt_s``: move by (target - believed), at most speed * dt, the target where
        its velocity takes it by the step's end; return the move."""
        move = np.zeros(3)
        if self.target is not None and self.target_velocity is not None:
            self.target = self.target + self.target_velocity * dt_s
        if self.target is not None:
            wanted = self.target - self.believed
            distance = float(np.linalg.norm(wanted))
            reach = speed_limit_m_s * dt_s
            move = wanted if distance <= reach else wanted * (reach / distance)
        self.believed = self.believed + move
        start = self.truth
        error = rng.normal(0.0, noise_m, 3) if noise_m > 0 else np.zeros(3)
        self.truth = self.truth + move + error
        self.velocity = (move + error) / dt_s
        self.path = np.vstack([start, self.truth])
        return move
