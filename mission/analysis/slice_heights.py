"""The heights a top view of a world is worth slicing at, read from its structure and its task:
under the deck, at the work UAV's heights and above the structure (``mission world --plot``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mission.world.model import World
from mission.world.surfaces import NONE_ABOVE_M, VerticalSurfaces

WORK_HEIGHTS = 2  # the work UAV's most used heights sliced at, at most
ABOVE_M = 2.0  # the slice above the structure: this far over its top
FOOTPRINT_STEP_M = 1.0  # the columns the deck's underside is looked for in


@dataclass(frozen=True)
class SliceHeight:
    """A height to slice at and why: what a reader sees there."""

    z_m: float
    why: str


def slice_heights(world: World) -> list[SliceHeight]:
    """Under the deck (half its underside's height), the work UAV's most used heights and
    above the structure, low to high; of two in one voxel layer, the first said."""
    bounds = world.structure.bounds
    top = float(bounds[1, 2])
    wanted = []
    underside = deck_underside(world)
    if underside is not None:
        wanted.append(
            SliceHeight(underside / 2, f"under the deck (its underside at {underside:g} m)")
        )
    heights = [round(float(p[2]), 2) for p in world.scenario.task.work_waypoints_m]
    values, counts = np.unique(heights, return_counts=True)
    for z in values[np.argsort(-counts, kind="stable")][:WORK_HEIGHTS]:
        wanted.append(SliceHeight(float(z), f"the work UAV's height ({z:g} m)"))
    ceiling = world.scenario.world.workspace.max_m[2]
    above = min(top + ABOVE_M, ceiling - world.scenario.map.voxel_size_m / 2)
    wanted.append(SliceHeight(above, f"above the structure (its top at {top:g} m)"))
    grid = world.sigma0_map().grid
    layers: dict[int, SliceHeight] = {}
    for height in wanted:
        layers.setdefault(int(grid.index_of(np.array([[0.0, 0.0, height.z_m]]))[0, 2]), height)
    return [layers[k] for k in sorted(layers)]


def deck_underside(world: World) -> float | None:
    """The height of the lowest surface over the ground under the structure (a deck's
    underside), the median over its footprint; None where nothing overhangs the ground."""
    low, high = world.structure.bounds
    xs = np.arange(low[0], high[0] + 1e-9, FOOTPRINT_STEP_M)
    ys = np.arange(low[1], high[1] + 1e-9, FOOTPRINT_STEP_M)
    grid_x, grid_y = np.meshgrid(xs, ys, indexing="ij")
    ground = np.column_stack((grid_x.ravel(), grid_y.ravel(), np.full(grid_x.size, 0.01)))
    ground = ground[~world.structure.contains(ground)]  # inside a pier: no underside
    above, _ = VerticalSurfaces(world.structure).heights(ground)
    overhead = above[(above < NONE_ABOVE_M) & (above > 0.1)]
    return float(np.median(overhead)) if len(overhead) else None
