"""The structure as a triangle mesh, with the ray queries the models need.

Box primitives are triangulated here, so a world of boxes never imports trimesh (about half a
second of start-up in each of a run's five processes); mesh files, the trimesh view of the
mesh and the fallback ray tracer import it when they are used.
"""

from __future__ import annotations

from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from mission.config.errors import ScenarioError
from mission.config.settings import MAX_COORDINATE_M, BoxPrimitive, StructureSettings
from mission.world.rays import best_ray_engine

if TYPE_CHECKING:
    import trimesh

_EPS = 1e-6
_MESH_SUFFIXES = (".stl", ".obj", ".ply")


class Structure:
    """A static structure (bridge, wall, ...) that blocks satellite signals and sight lines."""

    def __init__(
        self,
        vertices: np.ndarray,
        faces: np.ndarray,
        boxes: list[BoxPrimitive],
    ) -> None:
        """``vertices`` (n, 3) and ``faces`` (m, 3) are everything that occludes; ``boxes`` and
        the watertight connected parts of the mesh file answer inside/outside queries."""
        self.vertices = np.asarray(vertices, dtype=float).reshape(-1, 3)
        self.faces = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
        self.rays = best_ray_engine(self.vertices, self.faces)
        self.boxes = boxes
        self.box_low = np.array([b.min_m for b in boxes], dtype=float).reshape(-1, 3)
        self.box_high = np.array([b.max_m for b in boxes], dtype=float).reshape(-1, 3)
        # each box's inside as contains() tests it, in plain floats for a single point
        self._insides = list(
            zip((self.box_low + _EPS).tolist(), (self.box_high - _EPS).tolist(), strict=True)
        )

    @cached_property
    def mesh(self) -> trimesh.Trimesh:
        """The occluding triangles as a trimesh mesh (for plots, proximity and the fallback)."""
        import trimesh

        return trimesh.Trimesh(self.vertices, self.faces, process=False)

    @cached_property
    def file_mesh(self) -> trimesh.Trimesh | None:
        """The mesh file's triangles alone (those after the box primitives') as a trimesh mesh
        of the vertices they use; None without a mesh file."""
        extra = self.faces[len(_BOX_FACES) * len(self.boxes) :]
        if not len(extra):
            return None
        import trimesh  # a mesh file's world imports it anyway

        used = np.unique(extra)
        remap = np.full(len(self.vertices), -1)
        remap[used] = np.arange(len(used))
        return trimesh.Trimesh(self.vertices[used], remap[extra], process=False)

    @cached_property
    def file_parts(self) -> list[tuple[trimesh.Trimesh, bool]]:
        """The mesh file's connected parts (triangles sharing a vertex, once coincident
        vertices are merged), each with whether it is watertight (it has an inside): the
        pieces contact, the margins and inside/outside queries see."""
        mesh = self.file_mesh
        if mesh is None:
            return []
        merged = mesh.copy()
        merged.merge_vertices()
        return [(part, bool(part.is_watertight)) for part in merged.split(only_watertight=False)]

    @property
    def bounds(self) -> np.ndarray:
        """(2, 3) array: min and max corner of the structure."""
        return np.array([self.vertices.min(axis=0), self.vertices.max(axis=0)])

    @property
    def uses_embree(self) -> bool:
        """True when ray queries go through Embree."""
        return self.rays.name == "Embree"

    def rays_blocked(self, origins: np.ndarray, directions: np.ndarray) -> np.ndarray:
        """For each ray (origin, unit direction), True if it hits the structure anywhere."""
        origins = np.asarray(origins, dtype=float).reshape(-1, 3)
        directions = np.asarray(directions, dtype=float).reshape(-1, 3)
        if len(origins) == 0:
            return np.zeros(0, dtype=bool)
        return self.rays.occluded(origins, directions)

    def segment_blocked(self, start: np.ndarray, end: np.ndarray) -> bool:
        """:meth:`segments_blocked` of one segment (a vehicle's every step: the camera's sight
        line, the fence's path), without its broadcasting: the same operations, the same
        verdict."""
        delta = (np.asarray(end, dtype=float) - np.asarray(start, dtype=float)).reshape(1, 3)
        length = np.sqrt(np.einsum("ij,ij->i", delta, delta))
        if not length[0] > _EPS:
            return False
        origin = np.asarray(start, dtype=float).reshape(1, 3)
        return bool(self.rays.occluded(origin, delta / length[:, None], length - _EPS)[0])

    def segments_blocked(self, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
        """For each segment start -> end, True if the structure lies between the two points.

        The first hit along each ray decides; a point inside a closed solid sees its boundary
        first, so segments into or out of the structure count as blocked.
        """
        starts = np.atleast_2d(np.asarray(starts, dtype=float))
        ends = np.atleast_2d(np.asarray(ends, dtype=float))
        starts, ends = np.broadcast_arrays(starts, ends)
        delta = ends - starts
        length = np.sqrt(np.einsum("ij,ij->i", delta, delta))
        blocked = np.zeros(len(starts), dtype=bool)
        live = np.flatnonzero(length > _EPS)
        if len(live) == 0:
            return blocked
        directions = delta[live] / length[live, None]
        blocked[live] = self.rays.occluded(starts[live], directions, length[live] - _EPS)
        return blocked

    def contains(self, points: np.ndarray) -> np.ndarray:
        """True for points inside a solid of the structure (a box, or a watertight part of the
        mesh file)."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        if len(points) == 1 and not self.file_parts:  # a setpoint: plain floats, no set-up
            point = points[0].tolist()
            inside = any(
                all(lo < x < hi for lo, x, hi in zip(low, point, high, strict=True))
                for low, high in self._insides
            )
            return np.array([inside])
        inside = np.zeros(len(points), dtype=bool)
        if len(self.box_low):
            inside |= np.any(
                np.all(
                    (points[:, None, :] > self.box_low[None] + _EPS)
                    & (points[:, None, :] < self.box_high[None] - _EPS),
                    axis=2,
                ),
                axis=1,
            )
        for part, solid in self.file_parts:
            if solid:
                inside |= part.contains(points)
        return inside


def build_structure(settings: StructureSettings, source: str = "") -> Structure:
    """Build the structure's mesh from its primitives and mesh file."""
    parts = [_box_triangles(box) for box in settings.primitives]
    if settings.mesh_file is not None:
        file_mesh = load_mesh_file(Path(settings.mesh_file), source)
        parts.append((np.asarray(file_mesh.vertices), np.asarray(file_mesh.faces)))
    offsets = np.cumsum([0] + [len(vertices) for vertices, _ in parts[:-1]])
    vertices = np.vstack([vertices for vertices, _ in parts])
    faces = np.vstack([faces + offset for (_, faces), offset in zip(parts, offsets)])
    return Structure(vertices, faces, list(settings.primitives))


def load_mesh_file(path: Path, source: str = "") -> trimesh.Trimesh:
    """Load an STL/OBJ/PLY file as one triangle mesh; bad files raise ScenarioError."""
    import trimesh

    where = "world.structure.mesh_file"
    if path.suffix.lower() not in _MESH_SUFFIXES:
        raise ScenarioError(source or str(path), where, f"{path}: not an STL, OBJ or PLY file")
    try:
        with np.errstate(all="ignore"):  # absurd coordinates are reported below
            loaded = trimesh.load(str(path), force="mesh", process=True)
    except Exception as error:  # trimesh raises many types for malformed files
        raise ScenarioError(
            source or str(path), where, f"{path}: cannot read mesh ({type(error).__name__})"
        ) from None
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise ScenarioError(source or str(path), where, f"{path}: holds no triangles")
    if not np.all(np.isfinite(loaded.vertices)):
        raise ScenarioError(source or str(path), where, f"{path}: has non-finite vertices")
    farthest = float(np.abs(loaded.vertices).max())
    if farthest > MAX_COORDINATE_M:
        problem = f"{path}: a vertex lies {farthest:.3g} m from the anchor (metres, ENU expected)"
        raise ScenarioError(source or str(path), where, problem)
    return loaded


# The 12 triangles of a box over its corners (corner i has x from bit 0, y bit 1, z bit 2),
# wound counter-clockwise seen from outside.
_BOX_FACES = np.array(
    [
        [0, 2, 3], [0, 3, 1],  # z = min
        [4, 5, 7], [4, 7, 6],  # z = max
        [0, 1, 5], [0, 5, 4],  # y = min
        [2, 6, 7], [2, 7, 3],  # y = max
        [0, 4, 6], [0, 6, 2],  # x = min
        [1, 3, 7], [1, 7, 5],  # x = max
    ]
)  # fmt: skip


def _box_triangles(box: BoxPrimitive) -> tuple[np.ndarray, np.ndarray]:
    lo, hi = np.array(box.min_m, dtype=float), np.array(box.max_m, dtype=float)
    bits = (np.arange(8)[:, None] >> np.arange(3)) & 1
    return np.where(bits == 1, hi, lo), _BOX_FACES.copy()
