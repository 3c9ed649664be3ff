"""The world of a scenario: structure, sky, GNSS and camera models, multipath zones.

Both sides build it from the same scenario, each using only what it may know: a vehicle uses
the zones; the ground station never calls :meth:`World.zone_offset` or :meth:`World.in_zone`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from mission.config.scenario import load_scenario
from mission.config.settings import Scenario
from mission.world.camera import CameraModel
from mission.world.gnss import GnssModel
from mission.world.grid import VoxelGrid
from mission.world.sky import load_sky
from mission.world.structure import build_structure


@dataclass(frozen=True)
class Sigma0Map:
    """sigma_0 = sqrt(tr Sigma_GNSS) at every voxel centre, capped where there is no fix."""

    grid: VoxelGrid
    sigma_m: np.ndarray
    has_fix: np.ndarray
    n_visible: np.ndarray
    build_s: float


class World:
    """Everything physical about a scenario, built once."""

    def __init__(self, scenario: Scenario) -> None:
        self.scenario = scenario
        self.structure = build_structure(scenario.world.structure, scenario.source)
        self.sky = load_sky(scenario.sky)
        self.gnss = GnssModel(self.sky, self.structure, scenario.gnss)
        self.camera = CameraModel(scenario.camera, self.structure)
        self.workspace = scenario.world.workspace
        self._zone_min = np.array([z.min_m for z in scenario.world.zones]).reshape(-1, 3)
        self._zone_max = np.array([z.max_m for z in scenario.world.zones]).reshape(-1, 3)
        self._zone_offset = np.array([z.offset_m for z in scenario.world.zones]).reshape(-1, 3)
        self._zone_boxes = [(z.min_m, z.max_m) for z in scenario.world.zones]

    @classmethod
    def load(cls, name_or_path: str) -> World:
        """Load a scenario by name or path and build its world."""
        return cls(load_scenario(name_or_path))

    def zone_index(self, points: np.ndarray) -> np.ndarray:
        """Index of the first zone containing each point, -1 outside every zone (vehicle side)."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        if len(self._zone_min) == 0:
            return np.full(len(points), -1)
        if len(points) == 1:  # a vehicle's every step: plain floats beat numpy's set-up 10x
            point = points[0].tolist()
            for index, (low, high) in enumerate(self._zone_boxes):
                if all(lo <= x <= hi for lo, x, hi in zip(low, point, high)):
                    return np.array([index])
            return np.array([-1])
        inside = np.all(
            (points[:, None, :] >= self._zone_min[None])
            & (points[:, None, :] <= self._zone_max[None]),
            axis=2,
        )
        return np.where(inside.any(axis=1), inside.argmax(axis=1), -1)

    def in_zone(self, points: np.ndarray) -> np.ndarray:
        """True for points inside a multipath zone (vehicle side and analysis only)."""
        return self.zone_index(points) >= 0

    def zone_offset(self, points: np.ndarray) -> np.ndarray:
        """g_offset at each point: the containing zone's offset, zero elsewhere (vehicle side)."""
        index = self.zone_index(points)
        if len(index) == 1 and index[0] < 0:
            return np.zeros((1, 3))
        offsets = np.zeros((len(index), 3))
        inside = index >= 0
        offsets[inside] = self._zone_offset[index[inside]]
        return offsets

    def in_workspace(self, points: np.ndarray) -> np.ndarray:
        """True for points inside the workspace box."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        lo, hi = np.array(self.workspace.min_m), np.array(self.workspace.max_m)
        return np.all((points >= lo) & (points <= hi), axis=1)

    def map_grid(self) -> VoxelGrid:
        """The voxel grid of the GNSS-localizability map."""
        return VoxelGrid.over(self.workspace, self.scenario.map.voxel_size_m)

    def sigma0_map(self) -> Sigma0Map:
        """sigma_0 over the whole map grid (what G starts from), no-fix voxels capped."""
        start = time.perf_counter()
        grid = self.map_grid()
        centers = grid.centers().reshape(-1, 3)
        geometry = self.gnss.geometry(centers)
        sigma = self.scenario.gnss.sigma_uere_m * geometry.pdop
        cap = self.scenario.map.no_fix_sigma_m
        sigma = np.where(geometry.has_fix, np.minimum(sigma, cap), cap)
        return Sigma0Map(
            grid=grid,
            sigma_m=sigma.reshape(grid.shape),
            has_fix=geometry.has_fix.reshape(grid.shape),
            n_visible=geometry.n_visible.reshape(grid.shape),
            build_s=time.perf_counter() - start,
        )
