"""What the map G learned in a run, against the truth of where the multipath is: the voxels
whose G rose by more than a threshold, near a zone (within one voxel of its box) and
elsewhere. A map that learns the right thing raises voxels near the zones; a failed receiver
teaches it bad places elsewhere (docs/studies/faults).

:mod:`mission.studies.map_learning` tabulates it over a study's runs.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mission.world.model import World

RAISED_M = 0.3  # a voxel's G this much above where it started has learned something


def raised_voxels(run_dir: Path, world: World, threshold_m: float = RAISED_M) -> dict | None:
    """{"near_zone": n, "elsewhere": n} of a run's G (None without its snapshots)."""
    initial, final = (run_dir / "g" / f"G_{label}.npy" for label in ("initial", "final"))
    if not (initial.is_file() and final.is_file()):
        return None
    raised = (np.load(final) - np.load(initial)).reshape(-1) > threshold_m
    near = near_a_zone(world)
    return {"near_zone": int(raised[near].sum()), "elsewhere": int(raised[~near].sum())}


def run_raised_voxels(run_dir: Path, threshold_m: float = RAISED_M) -> dict | None:
    """:func:`raised_voxels` of a run folder, in the world of the scenario it ran
    (``scenario.yaml`` beside its tlog)."""
    return raised_voxels(run_dir, World.load(str(run_dir / "scenario.yaml")), threshold_m)


def near_a_zone(world: World) -> np.ndarray:
    """Per voxel of the map grid, whether its centre is within one voxel of a zone's box."""
    grid = world.map_grid()
    centres = grid.centers().reshape(-1, 3)
    near = np.zeros(len(centres), dtype=bool)
    for zone in world.scenario.world.zones:
        low, high = np.array(zone.min_m) - grid.voxel_m, np.array(zone.max_m) + grid.voxel_m
        near |= np.all((centres >= low) & (centres <= high), axis=1)
    return near
