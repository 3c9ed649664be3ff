"""Multipath zones: axis-aligned boxes where a GNSS fix is offset. Known to the simulated
vehicles and to analysis only, never to the ground station (it gets a
:class:`~mission.world.model.KnownWorld`, which has none)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from mission.config.settings import Zone


class MultipathZones:
    """Which zone holds a point, and the GNSS offset there."""

    def __init__(self, zones: Sequence[Zone]) -> None:
        self.zones = tuple(zones)
        self._min = np.array([z.min_m for z in zones]).reshape(-1, 3)
        self._max = np.array([z.max_m for z in zones]).reshape(-1, 3)
        self._offset = np.array([z.offset_m for z in zones]).reshape(-1, 3)
        self._boxes = [(z.min_m, z.max_m) for z in zones]

    def index(self, points: np.ndarray) -> np.ndarray:
        """Index of the first zone containing each point, -1 outside every zone."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        if len(self._min) == 0:
            return np.full(len(points), -1)
        if len(points) == 1:  # a vehicle's every step: plain floats beat numpy's set-up 10x
            point = points[0].tolist()
            for index, (low, high) in enumerate(self._boxes):
                if all(lo <= x <= hi for lo, x, hi in zip(low, point, high)):
                    return np.array([index])
            return np.array([-1])
        inside = np.all(
            (points[:, None, :] >= self._min[None]) & (points[:, None, :] <= self._max[None]),
            axis=2,
        )
        return np.where(inside.any(axis=1), inside.argmax(axis=1), -1)

    def contains(self, points: np.ndarray) -> np.ndarray:
        """True for points inside a zone."""
        return self.index(points) >= 0

    def offset(self, points: np.ndarray) -> np.ndarray:
        """g_offset at each point: the containing zone's offset, zero elsewhere."""
        index = self.index(points)
        if len(index) == 1 and index[0] < 0:
            return np.zeros((1, 3))
        offsets = np.zeros((len(index), 3))
        inside = index >= 0
        offsets[inside] = self._offset[index[inside]]
        return offsets
