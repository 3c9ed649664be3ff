"""First-order specular reflections of satellite signals off the structure and the ground,
found by the image method.

A satellite is far enough to be a direction ``e`` (unit, receiver to satellite). For a plane
with unit normal ``n`` facing the receiver at height ``h`` above it, the reflected signal
comes from the receiver's mirror image: it leaves the plane at the specular point

    s = p - 2 h n + (h / (n . e)) e

and travels ``2 h (n . e)`` further than the direct one (the excess path: ``2 h sin(el)`` off
the ground, ``2 d cos(el) cos(dAz)`` off a vertical wall). A reflection is received only when
the satellite lies on the receiver's side of the plane (``n . e > 0``), the specular point
lies on a face of the plane (the ground is one unbounded plane, z = 0), and neither leg, the
satellite to the specular point nor the specular point to the receiver, meets the structure.

Faces reflect on both sides (mesh files need not wind their triangles consistently); the
structure's coplanar triangles (a box face's two) form one reflecting plane, so a specular
point on their shared edge counts once. What depends on the satellites and the planes alone
(``n . e``) is computed once: the sky is one epoch.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mission.config.errors import ScenarioError
from mission.world.structure import Structure

LIFT_M = 1e-3  # legs start this far off a face, on its lit side, so that it does not block them
_MIN_HEIGHT_M = 10 * LIFT_M  # a receiver this close to a plane sees no reflection off it
_INSIDE_TOLERANCE = 1e-9  # barycentric slack: a point on a triangle's edge is on it
_MIN_AREA_M2 = 1e-12
_CHUNK_CANDIDATES = 400_000  # (point, satellite, plane, triangle) tuples at a time
MAX_PLANE_TRIANGLES = 16  # a reflecting plane's triangles tested at once
_SKY_M = 1.0e6  # a leg to a satellite: far beyond any structure


@dataclass(frozen=True)
class ReflectedPaths:
    """The received reflections at N points, one row per reflection."""

    point: np.ndarray  # (K,) index of the receiver point
    satellite: np.ndarray  # (K,) index of the satellite (into the directions given)
    plane: np.ndarray  # (K,) reflecting plane (the last index is the ground)
    excess_m: np.ndarray  # (K,) extra path over the direct one
    amplitude: np.ndarray  # (K,) field amplitude relative to a direct signal, antenna included
    specular_m: np.ndarray  # (K, 3) where the signal reflects


class Reflectors:
    """The structure's reflecting planes and the ground, with their surfaces' amplitudes, for
    one sky (the satellites' directions, fixed for the epoch)."""

    def __init__(
        self,
        structure: Structure,
        directions: np.ndarray,
        structure_amplitude: float,
        ground_amplitude: float,
        below_horizon_gain_db: float,
        source: str = "",
    ) -> None:
        self.structure = structure
        self.directions = np.atleast_2d(np.asarray(directions, dtype=float))
        normals, offsets, order, starts = _planes(structure.vertices, structure.faces, source)
        self.normals = np.vstack((normals, [[0.0, 0.0, 1.0]]))  # the ground last
        self.offsets = np.append(offsets, 0.0)
        self.ground = len(self.normals) - 1
        self.amplitudes = np.append(np.full(len(normals), structure_amplitude), ground_amplitude)
        self._below_horizon_gain = 10 ** (below_horizon_gain_db / 20)
        self._cosine = self.directions @ self.normals.T  # (S, G): n . e, once for the sky
        self._triangles = _PaddedTriangles(structure.vertices[structure.faces[order]], starts)

    def paths(self, points: np.ndarray) -> ReflectedPaths:
        """Every received first-order reflection at ``points`` (N, 3)."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        per_point = max(1, self._cosine.size * self._triangles.width)
        step = max(1, _CHUNK_CANDIDATES // per_point)
        parts = [
            self._paths_chunk(points[start : start + step], start)
            for start in range(0, len(points), step)
        ]
        if len(parts) == 1:
            return parts[0]
        if not parts:
            return _empty()
        return ReflectedPaths(*(np.concatenate([getattr(p, f) for p in parts]) for f in _FIELDS))

    def _paths_chunk(self, points: np.ndarray, first: int) -> ReflectedPaths:
        height = points @ self.normals.T - self.offsets  # (N, G), signed
        side = np.where(height >= 0, 1.0, -1.0)
        cosine = side[:, None, :] * self._cosine  # (N, S, G): n'.e, n' facing the receiver
        lit = (cosine > 0) & (np.abs(height) > _MIN_HEIGHT_M)[:, None, :]
        i, s, g = np.nonzero(lit)
        h = np.abs(height[i, g])
        cos = cosine[i, s, g]
        normal = side[i, g, None] * self.normals[g]
        specular = points[i] + (h / cos)[:, None] * self.directions[s] - (2 * h)[:, None] * normal
        on = g == self.ground
        faced = ~on
        on[faced] = self._triangles.contain(specular[faced], g[faced])
        i, s, g, h, cos, normal, specular = (a[on] for a in (i, s, g, h, cos, normal, specular))
        lifted = specular + LIFT_M * normal
        open_legs = ~self._legs_blocked(points[i], lifted, self.directions[s])
        i, s, g, specular = i[open_legs], s[open_legs], g[open_legs], specular[open_legs]
        excess = 2 * (h * cos)[open_legs]
        below = specular[:, 2] < points[i, 2]  # arriving from below the antenna's horizon
        amplitude = self.amplitudes[g] * np.where(below, self._below_horizon_gain, 1.0)
        return ReflectedPaths(i + first, s, g, excess, amplitude, specular)

    def _legs_blocked(self, points: np.ndarray, lifted: np.ndarray, sky: np.ndarray) -> np.ndarray:
        """Whether the leg from each point to its specular point, or the one from there to
        the satellite, meets the structure: both in one query."""
        n = len(points)
        if n == 0:
            return np.zeros(0, dtype=bool)
        delta = lifted - points
        length = np.sqrt(np.einsum("ij,ij->i", delta, delta))
        origins = np.concatenate((points, lifted))
        directions = np.concatenate((delta / length[:, None], sky))
        reach = np.concatenate((length, np.full(n, _SKY_M)))
        blocked = self.structure.rays.occluded(origins, directions, reach)
        return blocked[:n] | blocked[n:]


class _PaddedTriangles:
    """Each reflecting plane's triangles, padded to the largest count (a padding triangle
    holds nothing), for a point-on-face test without per-candidate loops."""

    def __init__(self, triangles: np.ndarray, starts: np.ndarray) -> None:
        counts = np.diff(starts)
        self.width = max(1, int(counts.max(initial=0)))
        planes = len(counts) + 1  # the ground's row stays empty
        slot = np.arange(len(triangles)) - np.repeat(starts[:-1], counts)
        plane = np.repeat(np.arange(len(counts)), counts)
        self.v0 = np.zeros((planes, self.width, 3))
        self.e1 = np.zeros((planes, self.width, 3))
        self.e2 = np.zeros((planes, self.width, 3))
        self.v0[plane, slot] = triangles[:, 0]
        self.e1[plane, slot] = triangles[:, 1] - triangles[:, 0]
        self.e2[plane, slot] = triangles[:, 2] - triangles[:, 0]
        self.d00 = np.einsum("ptj,ptj->pt", self.e1, self.e1)
        self.d01 = np.einsum("ptj,ptj->pt", self.e1, self.e2)
        self.d11 = np.einsum("ptj,ptj->pt", self.e2, self.e2)
        denominator = self.d00 * self.d11 - self.d01**2
        self.valid = denominator > 0
        self.inverse = np.where(self.valid, 1.0 / np.where(self.valid, denominator, 1.0), 0.0)

    def contain(self, points: np.ndarray, plane: np.ndarray) -> np.ndarray:
        """Whether each point (on its plane) lies on one of that plane's triangles."""
        offset = points[:, None, :] - self.v0[plane]  # (K, T, 3)
        d20 = np.einsum("ktj,ktj->kt", offset, self.e1[plane])
        d21 = np.einsum("ktj,ktj->kt", offset, self.e2[plane])
        v = (self.d11[plane] * d20 - self.d01[plane] * d21) * self.inverse[plane]
        w = (self.d00[plane] * d21 - self.d01[plane] * d20) * self.inverse[plane]
        inside = (v >= -_INSIDE_TOLERANCE) & (w >= -_INSIDE_TOLERANCE)
        inside &= (v + w <= 1 + _INSIDE_TOLERANCE) & self.valid[plane]
        return inside.any(axis=1)


def _split_wide(plane_of: np.ndarray) -> np.ndarray:
    """Plane numbers with no plane of more than MAX_PLANE_TRIANGLES triangles: a wide one
    (a finely meshed deck) becomes several of the same plane, so that the point-on-face test
    stays small (a specular point on an edge between two of them may then count twice)."""
    if len(plane_of) == 0:
        return plane_of
    order = np.argsort(plane_of, kind="stable")
    sorted_planes = plane_of[order]
    starts = np.searchsorted(sorted_planes, sorted_planes)  # each triangle's plane's first
    part = (np.arange(len(order)) - starts) // MAX_PLANE_TRIANGLES
    _, split = np.unique(np.column_stack((sorted_planes, part)), axis=0, return_inverse=True)
    result = np.empty_like(plane_of)
    result[order] = split.reshape(-1)
    return result


def check_reflecting_faces(structure: Structure, source: str = "") -> None:
    """Refuse (ScenarioError) a structure with a triangle that has no normal."""
    _planes(structure.vertices, structure.faces, source)


_FIELDS = ("point", "satellite", "plane", "excess_m", "amplitude", "specular_m")


def _empty() -> ReflectedPaths:
    none = np.zeros(0, dtype=int)
    return ReflectedPaths(none, none, none, np.zeros(0), np.zeros(0), np.zeros((0, 3)))


def _planes(
    vertices: np.ndarray, faces: np.ndarray, source: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The distinct planes of the triangles off the ground: unit normals (P, 3) with their
    first non-zero component positive, offsets (P,) (n . x = offset on the plane), those
    triangles' indices sorted by plane and each plane's first position in them (P + 1,)."""
    corners = vertices[faces]
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    doubled_area = np.linalg.norm(cross, axis=1)
    flat = np.flatnonzero(doubled_area / 2 <= _MIN_AREA_M2)
    if len(flat):
        raise ScenarioError(
            source,
            "world.structure.mesh_file",
            f"{len(flat)} triangle(s) have no normal (zero area; the first is face "
            f"{int(flat[0])}): a reflecting surface needs one; remove them from the mesh",
        )
    normal = cross / doubled_area[:, None]
    largest = np.argmax(np.abs(normal), axis=1)  # its sign decides: robust to float noise
    normal *= np.sign(normal[np.arange(len(normal)), largest])[:, None]
    offset = np.einsum("ij,ij->i", normal, corners[:, 0])
    # triangles on the ground's plane (a pier's footing) are the ground's to reflect
    kept = np.flatnonzero(~((np.abs(normal[:, 2] - 1) < 1e-9) & (np.abs(offset) < 1e-4)))
    key = np.column_stack((np.round(normal[kept], 6), np.round(offset[kept], 4)))
    _, plane_of = np.unique(key.reshape(-1, 4), axis=0, return_inverse=True)
    plane_of = _split_wide(plane_of.reshape(-1))
    ranked = np.argsort(plane_of, kind="stable")
    order = kept[ranked]
    starts = np.searchsorted(plane_of[ranked], np.arange(plane_of.max(initial=-1) + 2))
    first = order[starts[:-1]]
    return normal[first].reshape(-1, 3), offset[first], order, starts
