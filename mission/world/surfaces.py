"""The surfaces straight above and below points: the deck's underside a rotor flies under, the
ground or a pier's top it flies over (the ceiling and ground effects of a flying vehicle,
:mod:`vehicle_sim.dynamics.rigid_body`).

Box primitives answer in closed form (a box is above a point when the point's x and y lie within
its footprint and its underside is not below the point); a mesh file answers by casting a ray
up and one down from each point (trimesh's ray tracer: a world with a mesh file imports trimesh
anyway). The ground is the plane z = 0.
"""

from __future__ import annotations

import numpy as np

from mission.world.structure import Structure

NONE_ABOVE_M = 1.0e6  # the height reported where nothing is above


class VerticalSurfaces:
    """Heights of the nearest surface above and below points, for one structure."""

    def __init__(self, structure: Structure) -> None:
        self.low, self.high = structure.box_low, structure.box_high
        mesh = structure.file_mesh
        self._rays = None
        if mesh is not None:
            import trimesh

            self._rays = trimesh.ray.ray_triangle.RayMeshIntersector(mesh)

    def _footprint(self, points: np.ndarray) -> np.ndarray:
        """(points, boxes): whether each point's x and y lie within each box's footprint."""
        xy = points[:, None, :2]
        return np.all((xy >= self.low[None, :, :2]) & (xy <= self.high[None, :, :2]), axis=2)

    def heights(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """((n,), (n,)): the height of the nearest surface above each point
        (``NONE_ABOVE_M`` where the sky is open) and below it (the ground at least)."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        inside = self._footprint(points)
        z = points[:, 2:3]
        over = inside & (self.low[None, :, 2] >= z)
        under = inside & (self.high[None, :, 2] <= z)
        above = np.where(over, self.low[None, :, 2], NONE_ABOVE_M).min(axis=1, initial=NONE_ABOVE_M)
        below = np.where(under, self.high[None, :, 2], 0.0).max(axis=1, initial=0.0)
        if self._rays is not None:
            above = np.minimum(above, self._ray_heights(points, 1.0, NONE_ABOVE_M))
            below = np.maximum(below, self._ray_heights(points, -1.0, 0.0))
        return above, below

    def _ray_heights(self, points: np.ndarray, up: float, none: float) -> np.ndarray:
        """The height where a vertical ray from each point (``up`` +1 or -1) first meets the
        mesh file, ``none`` where it meets nothing."""
        directions = np.tile([0.0, 0.0, up], (len(points), 1))
        found = np.full(len(points), none)
        locations, ray_ids, _ = self._rays.intersects_location(points, directions)
        for ray, height in zip(ray_ids, locations[:, 2]):
            nearer = height < found[ray] if up > 0 else height > found[ray]
            found[ray] = height if nearer else found[ray]
        return found
