"""Placing the paper's multipath zones on a plan (docs/model.md, "Scenarios").

Along: a 1 m x 5 m x 2 m box (long side along the segment's main horizontal axis) enclosing a
stretch of support 1's path between two consecutive waypoints, and no other support's path.
Wall: a 5 m x 2 m x 5 m slab containing support 1's 6th waypoint and no other support's
waypoint. The searches run once, when a scenario is made; the results are written into the
scenario files in absolute coordinates, and tests check that they still hold.
"""

from __future__ import annotations

import itertools

import numpy as np

from mission.config.settings import Box
from mission.link.plan_files import Plan

GRID_M = 0.5
SAMPLE_M = 0.05


def path_samples(points: np.ndarray) -> np.ndarray:
    """Points every 5 cm along a polyline."""
    samples = [points[:1]]
    for a, b in itertools.pairwise(points):
        count = max(1, int(np.ceil(np.linalg.norm(b - a) / SAMPLE_M)))
        samples.append(a + (b - a) * (np.arange(1, count + 1) / count)[:, None])
    return np.vstack(samples)


def inside(box: Box, points: np.ndarray) -> np.ndarray:
    """True for points inside the closed box."""
    return np.all((points >= np.array(box.min_m)) & (points <= np.array(box.max_m)), axis=1)


def place_along(plan: Plan, workspace: Box, support: int = 0) -> tuple[Box, int]:
    """The Along zone and the (0-based) index i of the segment w_i -> w_{i+1} it encloses."""
    best: tuple[float, int, Box] | None = None
    for i in range(len(plan.supports[support]) - 1):
        try:
            score, box = _along_on_segment(plan, workspace, support, i)
        except ValueError:
            continue
        if best is None or score > best[0] + 1e-9:
            best = (score, i, box)
    if best is None:
        raise ValueError("no place for an Along zone on this plan")
    return best[2], best[1]


def place_along_pair(plan: Plan, workspace: Box) -> list[tuple[int, int, Box]]:
    """Two Along zones on two supports' paths, over the same or neighbouring segments (so both
    supports are in multipath at once), each enclosing its own support's path and no other's:
    [(support, segment index, zone), ...], 0-based. Prefers the same segment, then segments in
    the middle of the task, then the first supports."""
    options = {}
    for support, path in enumerate(plan.supports):
        for i in range(len(path) - 1):
            try:
                options[(support, i)] = _along_on_segment(plan, workspace, support, i)[1]
            except ValueError:
                continue
    middle = (len(plan.supports[0]) - 2) / 2
    pairs = [
        (abs(i - j), abs((i + j) / 2 - middle), n, m, i, j)
        for (n, i), (m, j) in itertools.combinations(sorted(options), 2)
        if n != m and abs(i - j) <= 1 and not _overlap(options[(n, i)], options[(m, j)])
    ]
    if not pairs:
        raise ValueError("no two supports' segments side by side can both get an Along zone")
    *_, n, m, i, j = min(pairs)
    return [(n, i, options[(n, i)]), (m, j, options[(m, j)])]


def _along_on_segment(plan: Plan, workspace: Box, support: int, i: int) -> tuple[float, Box]:
    """The best Along zone on support ``support``'s segment i and its score (metres of the
    segment enclosed, less 10 if it holds a waypoint)."""
    path = plan.supports[support]
    others = [path_samples(p) for n, p in enumerate(plan.supports) if n != support]
    a, b = path[i], path[i + 1]
    if np.linalg.norm((b - a)[:2]) < 2.0:
        raise ValueError("segment too short")
    axis = int(np.argmax(np.abs((b - a)[:2])))
    size = np.array([1.0, 1.0, 2.0])
    size[axis] = 5.0
    segment = path_samples(np.array([a, b]))
    best: tuple[float, Box] | None = None
    for center in _grid_centers(segment):
        box = _box(center, size)
        if not workspace.contains_box(box) or any(inside(box, o).any() for o in others):
            continue
        enclosed = inside(box, segment).sum() * SAMPLE_M
        score = enclosed - (10.0 if inside(box, path).any() else 0.0)
        if enclosed >= 2.0 and (best is None or score > best[0] + 1e-9):
            best = (score, box)
    if best is None:
        raise ValueError("no place on this segment")
    return best


def _overlap(a: Box, b: Box) -> bool:
    return all(a.min_m[k] < b.max_m[k] and b.min_m[k] < a.max_m[k] for k in range(3))


def place_wall(plan: Plan, workspace: Box, support: int = 0, waypoint: int = 5) -> Box:
    """The Wall zone around support ``support``'s waypoint ``waypoint`` (0-based)."""
    target = plan.supports[support][waypoint]
    others = np.vstack([p for n, p in enumerate(plan.supports) if n != support])
    other_paths = [path_samples(p) for n, p in enumerate(plan.supports) if n != support]
    best: tuple[float, Box] | None = None
    for size in (np.array([5.0, 2.0, 5.0]), np.array([2.0, 5.0, 5.0])):
        for dx, dy, dz in itertools.product(
            *(np.arange(-s / 2, s / 2 + 1e-9, GRID_M) for s in size)
        ):
            center = np.round((target + np.array([dx, dy, dz])) / GRID_M) * GRID_M
            box = _box(center, size)
            if not workspace.contains_box(box) or not inside(box, target[None])[0]:
                continue
            if inside(box, others).any():
                continue
            crossed = sum(inside(box, o).sum() for o in other_paths) * SAMPLE_M
            score = -crossed - 0.01 * float(np.linalg.norm(center - target))
            if best is None or score > best[0] + 1e-9:
                best = (score, box)
    if best is None:
        raise ValueError("no place for a Wall zone on this plan")
    return best[1]


def _grid_centers(samples: np.ndarray) -> np.ndarray:
    centers = np.round(samples / GRID_M) * GRID_M
    _, first = np.unique(centers, axis=0, return_index=True)
    return centers[np.sort(first)]


def _box(center: np.ndarray, size: np.ndarray) -> Box:
    lo, hi = center - size / 2, center + size / 2
    return Box(tuple(float(v) for v in lo), tuple(float(v) for v in hi))  # type: ignore[arg-type]
