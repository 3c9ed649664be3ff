"""The support MPC's cost in numpy over the whole map: an independent check of the casadi
model (tests, and the benchmark against scipy)."""

from __future__ import annotations

import itertools

import numpy as np

from ground_station.estimation.gnss_map import hermite_zero_slope
from mission.config.settings import ControlSettings
from mission.world.grid import VoxelGrid


def support_cost_numpy(
    path: np.ndarray,
    yhat: np.ndarray,
    targets: np.ndarray,
    terminal: np.ndarray,
    work: np.ndarray,
    blocked: np.ndarray,
    g_values: np.ndarray,
    grid: VoxelGrid,
    control: ControlSettings,
    anchors: np.ndarray | None = None,
) -> float:
    """The same cost in numpy over the whole map (an independent check of the casadi model);
    ``anchors`` default to the work UAV's path (the paper's penalty)."""
    c = control
    path = np.asarray(path, dtype=float).reshape(-1, 3)

    def sq(a: np.ndarray) -> float:
        return float(np.sum(np.asarray(a) ** 2))

    cost = c.w_interval * sq(yhat - path[0])
    cost += c.w_interval * sum(sq(b - a) for a, b in itertools.pairwise(path))
    terminal_sq = sq(terminal - path[-1])
    limit = c.d_max_support_m**2
    cost += (c.w_interval if terminal_sq <= limit else c.w_penalty) * terminal_sq
    cost += c.w_gnss * float(np.sum(hermite_zero_slope(g_values, grid, path)))
    cost += c.w_waypoint * sq(path - targets)
    anchors = work if anchors is None else anchors
    free = ~np.asarray(blocked, dtype=bool)
    cost += c.w_relative * float(np.sum((work - path)[free] ** 2))
    cost += c.w_penalty * float(np.sum((anchors - path)[~free] ** 2))
    return cost
