"""The true GNSS error field beside G in the 3-D view: recorded where the multipath
comes from geometry, each voxel's value the receiver's error at its centre, read back with
Rerun's own reader; absent with zones."""

from __future__ import annotations

import numpy as np

from mission.config.scenario import load_scenario
from mission.viewer import frame as f
from mission.viewer.recording import Recording
from mission.viewer.scene import GNSS_ERROR_SHOWN_M, build_scene
from mission.world.model import World
from tests.viewer.rrd import read_rrd


def test_the_error_field_is_recorded_voxel_for_voxel(tmp_path):
    world = World(load_scenario("river"))
    scene = build_scene(world.scenario, world)
    assert scene.gnss_error is not None
    indices, values = scene.gnss_error
    grid = world.map_grid()
    centers = grid.origin_m + (indices + 0.5) * grid.voxel_m
    sample = np.random.default_rng(0).choice(len(indices), 50, replace=False)
    again = np.linalg.norm(world.receiver.solve(centers[sample]).position_error_m, axis=1)
    assert np.allclose(again, values[sample], equal_nan=True)
    assert np.nanmin(values) >= GNSS_ERROR_SHOWN_M and np.nanmax(values) > 10.0  # under the deck
    path = tmp_path / "scene.rrd"
    Recording("river", scene, None, path).close()
    rows = read_rrd(path)[f"/{f.GNSS_ERROR_PATH}"]
    recorded = [c for name, c in rows.items() if name.endswith("voxel_indices")]
    assert recorded and np.array(recorded[0][0]).reshape(-1, 3).tolist() == indices.tolist()


def test_zones_draw_no_error_field(along):
    assert build_scene(along, World(along)).gnss_error is None
