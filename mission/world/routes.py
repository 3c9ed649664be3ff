"""Routes around the structure for a support that leaves the formation or comes back to it.

The formation's MPC plans a support locally, around the work UAV; a support flying to its own
inspection waypoint (on the far side of a pier, on top of the deck) needs a way around the
structure first. The map G's voxel grid is the graph: a voxel is free where its centre is at
least ``margin_m`` from the structure and the ground, and free voxels that touch (26
neighbours) are joined by their centres' distance times a cost per metre: more where the
GNSS is poor (a support routed where its fixes are poor or absent flies on a drifting
estimate: a route keeps to good GNSS where it can). Dijkstra's algorithm (scipy's csgraph)
gives the least costly way; the voxel path is then pulled straight: each corner is skipped where
the segment past it keeps the margin (sampled every quarter voxel). A route can also keep off
balls around other UAVs (their voxels taken out of the graph for that route).
"""

from __future__ import annotations

import itertools

import numpy as np

from mission.world.grid import VoxelGrid
from mission.world.model import KnownWorld
from mission.world.proximity import StructureProximity, segment_points

POOR_GNSS_COST = 100.0  # the most a metre costs: without a fix, or sigma_0 ten times good
ROUTE_EXTRA_M = 0.5  # a routed support flies without the MPC's map: this much wider a berth
NEIGHBOURS = np.array([d for d in itertools.product((-1, 0, 1), repeat=3) if any(d)])


class RouteMap:
    """Shortest routes between points through the free voxels of ``grid``."""

    def __init__(
        self,
        grid: VoxelGrid,
        proximity: StructureProximity,
        margin_m: float,
        cost: np.ndarray | None = None,
    ) -> None:
        self.grid, self.proximity, self.margin_m = grid, proximity, margin_m
        centres = grid.centers().reshape(-1, 3)
        self.free = proximity.clearance(centres) >= margin_m
        self.centres = centres
        # each voxel's cost per metre (1: good GNSS; up to POOR_GNSS_COST): an edge costs its
        # length times the dearer of its two voxels'
        self.cost = np.ones(len(centres)) if cost is None else np.asarray(cost, float).reshape(-1)
        # scipy only where routes are flown (~0.3 s to import), and all of it here, at
        # start-up: a route's first search does not pay for it inside a control cycle
        from scipy.sparse.csgraph import dijkstra

        self._dijkstra = dijkstra
        self.graph = self._graph()

    def _graph(self):
        from scipy.sparse import coo_matrix

        shape = np.array(self.grid.shape)
        index = np.arange(self.grid.n_voxels).reshape(self.grid.shape)
        rows, cols, weights = [], [], []
        for offset in NEIGHBOURS:
            low, high = np.maximum(0, -offset), shape - np.maximum(0, offset)
            here = index[low[0] : high[0], low[1] : high[1], low[2] : high[2]].ravel()
            shifted = index[
                low[0] + offset[0] : high[0] + offset[0],
                low[1] + offset[1] : high[1] + offset[1],
                low[2] + offset[2] : high[2] + offset[2],
            ].ravel()
            keep = self.free[here] & self.free[shifted]
            rows.append(here[keep])
            cols.append(shifted[keep])
            dearer = np.maximum(self.cost[here[keep]], self.cost[shifted[keep]])
            weights.append(dearer * self.grid.voxel_m * np.linalg.norm(offset))
        n = self.grid.n_voxels
        return coo_matrix(
            (np.concatenate(weights), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)
        ).tocsr()

    def cell_of(self, point: np.ndarray) -> int:
        """The free voxel nearest ``point`` (its own where that one is free)."""
        index = self.grid.index_of(np.asarray(point, dtype=float)[None])[0]
        cell = int(np.ravel_multi_index(tuple(index), self.grid.shape))
        if self.free[cell]:
            return cell
        free = np.flatnonzero(self.free)
        gaps = np.linalg.norm(self.centres[free] - np.asarray(point, dtype=float), axis=1)
        return int(free[np.argmin(gaps)])

    def lengths(self, sources: np.ndarray, targets: np.ndarray) -> np.ndarray:
        """(sources, targets): the length (m) of the route between each pair, from each
        point to its free voxel's centre, along the least costly voxel way, and on (infinity
        where none joins them)."""
        sources, targets = np.atleast_2d(sources), np.atleast_2d(targets)
        start_cells = [self.cell_of(p) for p in sources]
        end_cells = [self.cell_of(p) for p in targets]
        _, previous = self._dijkstra(self.graph, indices=start_cells, return_predecessors=True)
        result = np.full((len(sources), len(targets)), np.inf)
        for i, first in enumerate(start_cells):
            for j, last in enumerate(end_cells):
                cells = _walk_back(previous[i], first, last)
                if cells is not None:
                    corners = np.vstack([sources[i], self.centres[cells], targets[j]])
                    result[i, j] = float(np.sum(np.linalg.norm(np.diff(corners, axis=0), axis=1)))
        return result

    def route(
        self, start: np.ndarray, goal: np.ndarray, avoid: np.ndarray | None = None, radius_m=0.0
    ) -> np.ndarray | None:
        """Corners from ``start`` to ``goal`` (both included), pulled straight, and kept
        ``radius_m`` from each point of ``avoid`` (other UAVs) where the ends are; None where
        no free way joins them."""
        start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
        avoid = np.zeros((0, 3)) if avoid is None else np.atleast_2d(avoid)
        keep_off = Obstacles(avoid, radius_m)
        if self._clear(start, goal, keep_off):
            return np.vstack([start, goal])
        first, last = self.cell_of(start), self.cell_of(goal)
        graph = self.graph if not len(avoid) else self._without(keep_off, (first, last))
        _, previous = self._dijkstra(graph, indices=first, return_predecessors=True)
        cells = _walk_back(previous, first, last)
        if cells is None:
            return None
        corners = np.vstack([start, self.centres[cells], goal])
        return self._pulled(corners, keep_off)

    def structure_between(self, a: np.ndarray, b: np.ndarray, margin_m: float) -> bool:
        """Whether the straight way from ``a`` to ``b`` comes within ``margin_m`` of the
        structure (the ground not counted), sampled every quarter voxel: boxes by their
        distance in closed form, a mesh file by its closest points."""
        points = segment_points(a, b, self.grid.voxel_m / 4)
        low, high = self.proximity.low, self.proximity.high
        if len(low):
            outside = np.maximum(
                np.maximum(low[None] - points[:, None], points[:, None] - high[None]), 0
            )
            if np.any(np.einsum("pbk,pbk->pb", outside, outside) < margin_m**2):
                return True
        if not self.proximity.has_file_mesh:
            return False
        return bool(np.any(self.proximity.distance(points) < margin_m))

    def _without(self, keep_off: Obstacles, ends: tuple[int, int]):
        """The graph without the voxels ``keep_off`` covers (but the route's ends)."""
        from scipy.sparse import diags

        keep = ~keep_off.covers(self.centres)
        keep[list(ends)] = True
        mask = diags(keep.astype(float))
        graph = (mask @ self.graph @ mask).tocsr()
        graph.eliminate_zeros()
        return graph

    def _pulled(self, corners: np.ndarray, keep_off: Obstacles) -> np.ndarray:
        kept, i = [corners[0]], 0
        while i < len(corners) - 1:
            j = len(corners) - 1
            while j > i + 1 and not self._clear(corners[i], corners[j], keep_off):
                j -= 1
            kept.append(corners[j])
            i = j
        return np.array(kept)

    def leads_on(self, a: np.ndarray, b: np.ndarray) -> bool:
        """Whether the straight way from ``a`` to a route's corner ``b`` is one a route could
        take (the margin, GNSS no poorer than at its ends)."""
        nobody = Obstacles(np.zeros((0, 3)), 0.0)
        return self._clear(np.asarray(a, float), np.asarray(b, float), nobody)

    def _clear(self, a: np.ndarray, b: np.ndarray, keep_off: Obstacles) -> bool:
        """The segment keeps the margin; an end inside it is left (or neared) gaining (or
        losing) clearance at least half as fast as the way goes; it stays off the obstacles
        (but where its ends are) and out of GNSS poorer than at its ends."""
        points = segment_points(a, b, self.grid.voxel_m / 4)
        clearance = self.proximity.clearance(points)
        from_a = np.linalg.norm(points - a, axis=1)
        from_b = float(np.linalg.norm(b - a)) - from_a
        needed = np.minimum(
            self.margin_m,
            np.minimum(clearance[0] + 0.5 * from_a, clearance[-1] + 0.5 * from_b),
        )
        if not np.all(clearance >= needed - 1e-9):
            return False
        inside = keep_off.covers(points)
        if np.any(inside & ~inside[0] & ~inside[-1]):
            return False
        costs = self.cost_at(points)  # never through poorer GNSS than at its ends
        return bool(costs.max() <= max(costs[0], costs[-1]))

    def cost_at(self, points: np.ndarray) -> np.ndarray:
        """The cost per metre of the voxel of each point."""
        index = self.grid.index_of(points)
        return self.cost[np.ravel_multi_index(tuple(index.T), self.grid.shape)]


def _walk_back(previous: np.ndarray, first: int, last: int) -> list[int] | None:
    """The voxels from ``first`` to ``last`` by Dijkstra's predecessors (None: not joined)."""
    if first != last and previous[last] < 0:
        return None
    cells = [last]
    while cells[-1] != first:
        cells.append(int(previous[cells[-1]]))
    return cells[::-1]


class Obstacles:
    """Balls of ``radius_m`` around ``centres`` (other UAVs) a route keeps off."""

    def __init__(self, centres: np.ndarray, radius_m: float) -> None:
        self.centres, self.radius_m = centres, radius_m

    def covers(self, points: np.ndarray) -> np.ndarray:
        """Which points lie inside a ball."""
        if not len(self.centres):
            return np.zeros(len(points), dtype=bool)
        gaps = np.linalg.norm(points[:, None] - self.centres[None], axis=2)
        return np.any(gaps < self.radius_m, axis=1)


def route_map(world: KnownWorld, sigma0: np.ndarray | None = None) -> RouteMap:
    """Routes through the map's voxels that keep the clearance margin (at least a body's
    radius) widened by an estimate's allowance and ``ROUTE_EXTRA_M`` from the structure and
    the ground, and keep to good GNSS where they can: a metre costs the square of sigma_0 over
    ``roles.own_fix_max_sigma_m`` (a fix the ground station would trust), at least 1 and at
    most ``POOR_GNSS_COST`` (``sigma0``: the world's sigma_0 map, if already computed; no fix
    is its cap)."""
    control = world.scenario.control
    margin = max(control.clearance_m, world.scenario.vehicle.radius_m)
    if sigma0 is None:
        sigma0 = world.sigma0_map().sigma_m
    good = world.scenario.roles.own_fix_max_sigma_m
    return RouteMap(
        world.map_grid(),
        StructureProximity(world.structure),
        margin + control.allowance_m + ROUTE_EXTRA_M,
        np.clip((np.asarray(sigma0) / good) ** 2, 1.0, POOR_GNSS_COST),
    )
