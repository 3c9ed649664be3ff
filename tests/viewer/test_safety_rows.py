"""The view's margin rows against hand-computed answers: the closest approach and the least
clearance plotted, a line for each pair below the separation margin, the worst marked."""

from __future__ import annotations

import numpy as np
import trimesh

from mission.viewer import frame as f
from mission.viewer.safety_rows import SafetyRows


def test_pairs_below_the_margin_are_drawn_and_the_worst_approach_is_marked(along_world):
    rows = SafetyRows(along_world, ["work", "support-1", "support-2"])
    out = f.Frame()
    positions = {
        "work": np.array([0.0, -10.0, 5.0]),
        "support-1": np.array([1.5, -10.0, 5.0]),  # 1.5 m from the work UAV: below 2 m
        "support-2": np.array([0.0, -14.0, 5.0]),
    }
    rows.add(10.0, positions, out)
    rows.add(10.5, {**positions, "support-1": np.array([3.0, -10.0, 5.0])}, out)  # clear
    closest = out.scalars[f.scalar_path("margins", "closest_approach")]
    assert closest.times == [10.0, 10.5] and closest.values == [1.5, 3.0]
    (line,) = out.strips[f.below_margin_path("work", "support-1")].values
    np.testing.assert_array_equal(line, [positions["work"], positions["support-1"]])
    assert set(out.strips) == {f.below_margin_path("work", "support-1")}
    worst = out.points[f.WORST_PATH]
    assert worst.times == [10.0]  # the second cycle is no worse
    np.testing.assert_array_equal(worst.values[0], [0.75, -10.0, 5.0])
    query = trimesh.proximity.ProximityQuery(along_world.structure.mesh)
    every = np.array(list(positions.values()))
    expected = min(np.abs(query.signed_distance(every)).min(), every[:, 2].min())
    least = out.scalars[f.scalar_path("margins", "least_clearance")].values[0]
    assert abs(least - expected) < 1e-9
