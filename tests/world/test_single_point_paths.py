"""A vehicle's every step asks about one point or one sight line; those queries take plain-float
or unbroadcast paths. Each must give what the general path gives for the same point, bit for
bit: points inside, outside, on faces and corners of the boxes, and degenerate segments."""

from __future__ import annotations

import numpy as np
import pytest


def _points(world, rng: np.random.Generator, count: int = 4000) -> np.ndarray:
    """Points around and inside the structure, and exactly on its boxes' faces and corners."""
    low, high = world.structure.bounds
    around = rng.uniform(low - 4.0, high + 4.0, (count, 3))
    within = rng.uniform(low, high, (count // 4, 3))
    on_boxes = []
    for box in world.structure.boxes:
        lo, hi = np.array(box.min_m), np.array(box.max_m)
        mid = (lo + hi) / 2
        on_boxes += [
            lo,
            hi,
            [lo[0], mid[1], mid[2]],
            [mid[0], hi[1], mid[2]],
            [mid[0], mid[1], hi[2]],
        ]
        for axis in range(3):  # at the inside test's margin on one axis, inside on the others
            for margin in (lo[axis] + 1e-6, hi[axis] - 1e-6):
                point = mid.copy()
                point[axis] = margin
                on_boxes.append(point)
    return np.vstack([around, within, np.array(on_boxes, dtype=float)])


def test_one_point_is_inside_the_structure_exactly_when_the_batch_says_so(along_world):
    structure = along_world.structure
    points = _points(along_world, np.random.default_rng(1))
    batch = structure.contains(points)
    alone = np.array([structure.contains(p[None])[0] for p in points])
    assert np.array_equal(alone, batch)
    assert 0 < batch.sum() < len(points)  # both answers occur


def test_one_points_distance_to_the_boxes_is_the_batchs_bit_for_bit(along_world):
    from mission.world.proximity import StructureProximity

    proximity = StructureProximity(along_world.structure)
    points = _points(along_world, np.random.default_rng(2))
    batch = proximity.closest(points)[0].min(axis=1)
    alone = np.array([proximity.distance(p[None])[0] for p in points])
    assert np.array_equal(alone.view(np.int64), batch.view(np.int64))
    assert (batch < 0).any() and (batch == 0).any() and (batch > 0).any()
    assert np.isnan(proximity.distance(np.array([[np.nan, 0.0, 5.0]]))[0])  # the general path


def test_signed_zeros_on_touching_boxes_give_the_batchs_distance_bit_for_bit():
    """Points on the faces, edges and corners of two boxes that touch at the origin, with
    every coordinate +0.0 or -0.0 where it is zero: the distance's sign bit as numpy's
    maximum and minimum leave it."""
    import itertools

    from mission.config.settings import BoxPrimitive, StructureSettings
    from mission.world.proximity import StructureProximity
    from mission.world.structure import build_structure

    boxes = [
        BoxPrimitive("a", (-4.0, -4.0, 0.0), (0.0, 0.0, 5.0)),
        BoxPrimitive("b", (0.0, 0.0, 0.0), (2.0, 2.0, 1.0)),
    ]
    proximity = StructureProximity(build_structure(StructureSettings(None, boxes)))
    values = [-0.0, 0.0, -4.0, -1.0, 1.0, 2.0, 5.0]
    points = np.array(list(itertools.product(values, repeat=3)))
    batch = proximity.closest(points)[0].min(axis=1)
    alone = np.array([proximity.distance(p[None])[0] for p in points])
    assert np.array_equal(alone.view(np.int64), batch.view(np.int64))
    assert (np.signbit(batch) & (batch == 0)).any() and ((batch == 0) & ~np.signbit(batch)).any()


def test_one_sight_line_is_blocked_exactly_when_the_batch_says_so(along_world):
    structure = along_world.structure
    rng = np.random.default_rng(3)
    starts = _points(along_world, rng, 2000)
    ends = np.vstack([_points(along_world, rng, 2000)[: len(starts) - 3], starts[:3]])  # 3 empty
    batch = structure.segments_blocked(starts, ends)
    alone = np.array([structure.segment_blocked(a, b) for a, b in zip(starts, ends, strict=True)])
    assert np.array_equal(alone, batch)
    assert 0 < batch.sum() < len(batch)
    assert not structure.segment_blocked(starts[0], starts[0])  # no length: nothing between


def test_one_points_satellites_and_workspace_are_the_batchs(along_world):
    points = _points(along_world, np.random.default_rng(4), 400)
    gnss, sky = along_world.gnss, along_world.sky
    batch = gnss.visibility(points)
    alone = np.vstack([gnss.visibility(p[None]) for p in points])
    assert np.array_equal(alone, batch)
    assert batch.any() and not batch.all()
    above = np.flatnonzero(sky.above_mask)  # made here, not by the model's cache
    blocked = along_world.structure.rays_blocked(
        np.repeat(points, len(above), axis=0), np.tile(sky.directions_enu[above], (len(points), 1))
    ).reshape(len(points), -1)
    assert np.array_equal(batch[:, above], ~blocked) and not batch[:, ~sky.above_mask].any()
    inside = along_world.in_workspace(points)
    assert np.array_equal(np.array([along_world.in_workspace(p)[0] for p in points]), inside)
    assert inside.any() and not inside.all()


@pytest.mark.parametrize("axis", range(3))
def test_a_point_on_the_workspaces_boundary_is_inside_it(along_world, axis):
    corner = np.array(along_world.workspace.max_m, dtype=float)
    assert along_world.in_workspace(corner)[0]
    corner[axis] = np.nextafter(corner[axis], np.inf)
    assert not along_world.in_workspace(corner)[0]
