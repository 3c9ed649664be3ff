"""MPC of the work UAV (paper 4.2.1, Algorithm 1 as docs/model.md, "MPCs (4.2.1, 4.2.2)",
reconstructs it)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class WorkPrediction:
    """V^(w) (U+1, 3) and the target index k_u of each step (0-based waypoint indices)."""

    path: np.ndarray
    indices: np.ndarray

    @property
    def command(self) -> np.ndarray:
        """The movement command: the first predicted position."""
        return self.path[0]


def predict_work(
    xhat: np.ndarray,
    k_now: int,
    waypoints: np.ndarray,
    horizon: int,
    d_max_m: float,
    arrival_tol_m: float,
) -> WorkPrediction:
    """Greedy steps of at most d_max toward w_k; k advances when a predicted step arrives."""
    v = np.asarray(xhat, dtype=float).copy()
    k = k_now
    last = len(waypoints) - 1
    path, indices = [], []
    for _ in range(horizon + 1):
        step = waypoints[k] - v
        distance = float(np.linalg.norm(step))
        if distance > 0:
            v = v + step * min(1.0, d_max_m / distance)
        path.append(v.copy())
        indices.append(k)
        if np.linalg.norm(waypoints[k] - v) < arrival_tol_m and k < last:
            k += 1
    return WorkPrediction(np.array(path), np.array(indices))


def hold_work(position: np.ndarray, k_now: int, horizon: int) -> WorkPrediction:
    """The work UAV holding at ``position`` over the horizon (a blind cycle)."""
    path = np.repeat(np.asarray(position, dtype=float).reshape(1, 3), horizon + 1, axis=0)
    return WorkPrediction(path, np.full(horizon + 1, k_now))
