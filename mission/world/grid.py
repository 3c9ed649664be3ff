"""A regular voxel grid over the workspace box (the support of the map G)."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from mission.config.settings import Box


@dataclass(frozen=True)
class VoxelGrid:
    """Voxels of side ``voxel_m`` tiling the workspace from its min corner."""

    origin_m: np.ndarray
    voxel_m: float
    shape: tuple[int, int, int]

    @classmethod
    def over(cls, box: Box, voxel_m: float) -> VoxelGrid:
        """Grid covering ``box``; a partial voxel at the far faces is dropped."""
        size = np.array(box.size_m)
        shape = tuple(max(1, int(np.floor(s / voxel_m + 1e-9))) for s in size)
        return cls(np.array(box.min_m, dtype=float), float(voxel_m), shape)  # type: ignore[arg-type]

    @functools.cached_property
    def index_limits(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per axis: the highest fractional index, the highest base of an interpolation's
        cell and the highest index (read-only; the interpolants' bounds, made once)."""
        size = np.array(self.shape)
        limits = ((size - 1).astype(float), np.maximum(size - 2, 0), size - 1)
        for array in limits:
            array.flags.writeable = False
        return limits

    @property
    def n_voxels(self) -> int:
        """Number of voxels."""
        return int(np.prod(self.shape))

    def axis_centers(self, axis: int) -> np.ndarray:
        """Centre coordinates along one axis."""
        return self.origin_m[axis] + self.voxel_m * (np.arange(self.shape[axis]) + 0.5)

    def centers(self) -> np.ndarray:
        """(nx, ny, nz, 3) voxel centres."""
        grids = np.meshgrid(*(self.axis_centers(a) for a in range(3)), indexing="ij")
        return np.stack(grids, axis=-1)

    def index_of(self, points: np.ndarray) -> np.ndarray:
        """(N, 3) integer index of the voxel containing each point, clipped to the grid."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        index = np.floor((points - self.origin_m) / self.voxel_m).astype(int)
        return np.clip(index, 0, np.array(self.shape) - 1)
