"""What G learned, split by the truth of where the zones are."""

from __future__ import annotations

import numpy as np

from mission.analysis.map_learning import RAISED_M, near_a_zone, raised_voxels


def test_raised_voxels_are_counted_near_the_zone_and_elsewhere(along_world, tmp_path):
    grid = along_world.map_grid()
    near = near_a_zone(along_world)
    assert 0 < near.sum() < near.size
    initial = np.ones(grid.shape)
    final = initial.copy().reshape(-1)
    final[np.flatnonzero(near)[:3]] += 2 * RAISED_M  # three near the zone
    final[np.flatnonzero(~near)[:5]] += 2 * RAISED_M  # five elsewhere
    final[np.flatnonzero(~near)[5]] += RAISED_M / 2  # one below the threshold
    (tmp_path / "g").mkdir()
    np.save(tmp_path / "g" / "G_initial.npy", initial)
    np.save(tmp_path / "g" / "G_final.npy", final.reshape(grid.shape))
    assert raised_voxels(tmp_path, along_world) == {"near_zone": 3, "elsewhere": 5}
    assert raised_voxels(tmp_path / "nothing", along_world) is None
