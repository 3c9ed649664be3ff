"""How far points are from the structure and the ground, and the half-spaces that keep a point
clear of them: what contact detection (the vehicles) and the MPCs' margins (the ground station)
share.

The structure is a set of convex pieces: each box primitive (distances in closed form, signed:
negative inside), and each connected part of a mesh file (trimesh's closest points, unsigned; a
watertight part's inside counts as negative), so that a mesh of the same bodies as the boxes
gives the same pieces. The ground is the plane z = 0.

A *separating half-space* of a point g from a convex piece is {x : n.x >= n.c}, c the piece's
point closest to g and n the unit vector from c to g (inside a box, the normal of the face it is
nearest to). The piece lies wholly on the other side, so any x with n.x >= n.c + m is at least
m from the piece: a linear constraint that is conservative, never optimistic (for a part of a
mesh file that is not convex, it holds near c only).
"""

from __future__ import annotations

import math

import numpy as np

from mission.world.structure import Structure


class StructureProximity:
    """Distances from points to the structure's convex pieces, and separating half-spaces."""

    def __init__(self, structure: Structure) -> None:
        self.low, self.high = structure.box_low, structure.box_high
        self._file_mesh = structure.file_mesh
        self._parts = structure.file_parts
        self._boxes = list(zip(self.low.tolist(), self.high.tolist(), strict=True))

    @property
    def has_file_mesh(self) -> bool:
        """Whether a mesh file is one of the pieces (not in closed form)."""
        return self._file_mesh is not None

    @property
    def pieces(self) -> int:
        """How many pieces: the boxes, and the connected parts of the mesh file."""
        return len(self.low) + len(self._parts)

    def closest(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per point and piece: the signed distance (points, pieces), the closest point on the
        piece (points, pieces, 3) and the outward unit normal there (points, pieces, 3)."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        below = self.low[None] - points[:, None]  # > 0 where the point is below a box's side
        above = points[:, None] - self.high[None]
        outside = np.maximum(np.maximum(below, above), 0.0)
        out_distance = np.linalg.norm(outside, axis=2)
        depth = np.maximum(below, above)  # per axis: minus the distance to the nearer face
        inside = out_distance == 0.0
        nearest_face = np.max(depth, axis=2)  # minus the depth below the nearest face
        distance = np.where(inside, nearest_face, out_distance)
        closest = np.clip(points[:, None], self.low[None], self.high[None])
        normals = np.divide(
            points[:, None] - closest,
            out_distance[..., None],
            out=np.zeros_like(closest),
            where=out_distance[..., None] > 0,
        )
        if inside.any():  # inside: out through the nearest face
            axis = np.argmax(depth, axis=2)
            sign = np.where(
                np.take_along_axis(above, axis[..., None], 2)[..., 0]
                >= np.take_along_axis(below, axis[..., None], 2)[..., 0],
                1.0,
                -1.0,
            )
            face_normals = np.eye(3)[axis] * sign[..., None]
            high = np.take_along_axis(np.broadcast_to(self.high, depth.shape), axis[..., None], 2)
            low = np.take_along_axis(np.broadcast_to(self.low, depth.shape), axis[..., None], 2)
            face = np.where(sign > 0, high[..., 0], low[..., 0])
            projected = closest.copy()
            np.put_along_axis(projected, axis[..., None], face[..., None], axis=2)
            normals = np.where(inside[..., None], face_normals, normals)
            closest = np.where(inside[..., None], projected, closest)
        for part, solid in self._parts:
            on_part, gap, _ = part.nearest.on_surface(points)
            direction = points - on_part
            normal = np.divide(
                direction, gap[:, None], out=np.zeros_like(direction), where=gap[:, None] > 0
            )
            if solid:
                within = part.contains(points)
                gap = np.where(within, -gap, gap)
                normal = np.where(within[:, None], -normal, normal)
            distance = np.column_stack([distance, gap])
            closest = np.concatenate([closest, on_part[:, None]], axis=1)
            normals = np.concatenate([normals, normal[:, None]], axis=1)
        return distance, closest, normals

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Signed distance from each point to the structure (negative inside a box); +inf for
        a world with no structure."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        if self.pieces == 0:
            return np.full(len(points), np.inf)
        if len(points) == 1 and not self._parts and np.isfinite(points).all():
            return np.array([self._box_distance(points[0].tolist())])
        return self.closest(points)[0].min(axis=1)

    def _box_distance(self, point: list[float]) -> float:
        """The least signed distance from one finite point to the boxes, as :meth:`closest`
        gives it, in plain floats (a vehicle's every step): the same operations in the same
        order (each squared gap summed x, y, z, as numpy sums three; the larger and smaller
        of two as numpy's ``maximum`` and ``minimum`` pick them, the second on a tie of 0.0
        and -0.0), so the same value, bit for bit."""
        least = None
        for low, high in self._boxes:
            below = [low[k] - point[k] for k in range(3)]
            above = [point[k] - high[k] for k in range(3)]
            depth = [_larger(below[k], above[k]) for k in range(3)]
            out = [_larger(depth[k], 0.0) for k in range(3)]
            gap = math.sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2])
            distance = _larger(_larger(depth[0], depth[1]), depth[2]) if gap == 0.0 else gap
            least = distance if least is None else _smaller(least, distance)
        return least

    def clearance(self, points: np.ndarray) -> np.ndarray:
        """Distance from each point to whatever is nearer, the structure or the ground."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        return np.minimum(self.distance(points), points[:, 2])


def _larger(a: float, b: float) -> float:
    """numpy's ``maximum`` of two finite floats: ``a`` only if it is larger."""
    return a if a > b else b


def _smaller(a: float, b: float) -> float:
    """numpy's ``minimum`` of two finite floats: ``a`` only if it is smaller."""
    return a if a < b else b


def segment_points(start: np.ndarray, end: np.ndarray, spacing_m: float) -> np.ndarray:
    """Points from ``start`` to ``end`` (both included) at most ``spacing_m`` apart."""
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    count = int(np.ceil(np.linalg.norm(end - start) / spacing_m)) + 1
    fractions = np.linspace(0.0, 1.0, max(count, 2))
    return start + (end - start) * fractions[:, None]


def closest_approach(
    a0: np.ndarray, a1: np.ndarray, b0: np.ndarray, b1: np.ndarray
) -> tuple[float, float]:
    """Two points moving straight from a0 to a1 and from b0 to b1 over the same interval:
    (their least distance, the fraction of the interval when it happens). Symmetric in a and
    b bit for bit (the relative motion is negated exactly)."""
    d0 = np.asarray(a0, dtype=float) - np.asarray(b0, dtype=float)
    d1 = np.asarray(a1, dtype=float) - np.asarray(b1, dtype=float)
    change = d1 - d0
    speed_sq = float(change @ change)
    fraction = 0.0 if speed_sq == 0 else float(np.clip(-(d0 @ change) / speed_sq, 0.0, 1.0))
    return float(np.linalg.norm(d0 + fraction * change)), fraction
