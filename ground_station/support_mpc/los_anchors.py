"""Where the support MPC's line-of-sight penalty pulls a step that cannot see the work UAV.

``paper``: the work UAV itself, as the paper writes the penalty. ``visible-point`` (ours): the
step itself when it sees the work UAV (a step held blocked by the re-solve), else the nearest
point around it (26 directions, shells of 0.5 m up to the horizon's reach) that sees the work
UAV and has a usable prior fix, the nearest to the work UAV among equals; the pre-planned
waypoint when there is none.
"""

from __future__ import annotations

import itertools

import numpy as np

from ground_station.estimation.gnss_map import hermite_zero_slope
from mission.config.settings import ControlSettings
from mission.world.camera import CameraModel
from mission.world.grid import VoxelGrid


class LosAnchors:
    """The anchors of the blocked steps of a guess."""

    def __init__(
        self,
        control: ControlSettings,
        camera: CameraModel,
        grid: VoxelGrid,
        sigma0: np.ndarray | None,
    ) -> None:
        self.control = control
        self.camera = camera
        self.grid = grid
        self.sigma0 = sigma0
        cube = np.array(list(itertools.product((-1.0, 0.0, 1.0), repeat=3)))
        cube = cube[np.any(cube != 0, axis=1)]
        self._directions = cube / np.linalg.norm(cube, axis=1, keepdims=True)
        reach = control.horizon_steps * control.d_max_support_m
        self._shell_radii = np.arange(0.5, reach + 1e-9, 0.5)
        self._first_shell = self._shell_radii[0] * self._directions

    def __call__(
        self, guess: np.ndarray, work: np.ndarray, targets: np.ndarray, blocked: np.ndarray
    ) -> np.ndarray:
        """Where the LOS penalty pulls each blocked step of ``guess`` (the work UAV's
        position for the steps that see it)."""
        anchors = np.array(work, dtype=float)
        if self.control.los_penalty == "paper" or not np.any(blocked):
            return anchors
        # Every blocked step and its first shell judged in one evaluation (nine anchors in ten
        # are found there; a point's verdict does not depend on the points judged with it).
        steps = np.flatnonzero(blocked)
        firsts = guess[steps, None] + np.vstack([np.zeros((1, 3)), self._first_shell])[None]
        sees = self._sees_with_a_fix(
            firsts.reshape(-1, 3), np.repeat(work[steps], len(firsts[0]), axis=0)
        ).reshape(len(steps), -1)
        for u, first, seen in zip(steps, firsts, sees, strict=True):
            anchors[u] = self._nearest_visible(first, seen, work[u], targets[u])
        return anchors

    def _nearest_visible(
        self, first: np.ndarray, sees: np.ndarray, work: np.ndarray, fallback: np.ndarray
    ) -> np.ndarray:
        """The step itself (``first[0]``) if it sees the work UAV, else the nearest seeing
        point of the first shell (``first[1:]``, judged in ``sees``), then of the next
        shells."""
        start = first[0]
        if sees[0]:
            return start
        shells = [(first[1:], sees[1:])]
        shells += [(start + r * self._directions, None) for r in self._shell_radii[1:]]
        for points, verdict in shells:
            seen = points[self._sees_with_a_fix(points, work) if verdict is None else verdict]
            if len(seen):
                return seen[np.argmin(np.linalg.norm(seen - work, axis=1))]
        return fallback

    def _sees_with_a_fix(self, points: np.ndarray, work: np.ndarray) -> np.ndarray:
        """Where a point has a usable prior fix and sees the work UAV."""
        usable = np.ones(len(points), dtype=bool)
        if self.sigma0 is not None:
            sigma = hermite_zero_slope(self.sigma0, self.grid, points)
            usable = sigma <= self.control.support_max_sigma0_m
        return usable & self.camera.observable(points, np.atleast_2d(work))
