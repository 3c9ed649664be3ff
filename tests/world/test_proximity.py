"""Distances to the structure against trimesh's, the separating half-spaces' promise (a point
on their far side is at least the margin from the piece), and the closest approach of two
straight motions against a dense sampling."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from mission.world.proximity import StructureProximity, closest_approach, segment_points


def test_distances_match_trimesh_outside_and_inside(along_world):
    proximity = StructureProximity(along_world.structure)
    rng = np.random.default_rng(0)
    points = rng.uniform([-25, -20, 0], [25, 20, 20], (3000, 3))
    ours = proximity.distance(points)
    theirs = -trimesh.proximity.ProximityQuery(along_world.structure.mesh).signed_distance(points)
    outside = ours > 0
    assert outside.sum() > 2500 and (~outside).sum() > 10
    np.testing.assert_allclose(ours[outside], theirs[outside], atol=1e-9)
    # inside a box: minus the depth below its nearest face (the piers touch the deck, so the
    # union's surface and a box's can differ there: compare with the box alone)
    deck = along_world.structure.boxes[0]
    low, high = np.array(deck.min_m), np.array(deck.max_m)
    inside = rng.uniform(low + 0.01, high - 0.01, (200, 3))
    depth = np.minimum(inside - low, high - inside).min(axis=1)
    np.testing.assert_allclose(proximity.distance(inside), -depth, atol=1e-12)


def test_a_separating_half_space_keeps_its_margin_from_the_piece(along_world):
    proximity = StructureProximity(along_world.structure)
    rng = np.random.default_rng(1)
    guesses = rng.uniform([-25, -20, 0], [25, 20, 20], (300, 3))
    distance, closest, normals = proximity.closest(guesses)
    margin = 0.5
    for piece in range(proximity.pieces):
        n, c = normals[:, piece], closest[:, piece]
        # points anywhere on the far side of each half-space, shifted out by the margin
        offsets = rng.uniform(0, 5, (len(guesses), 3))
        offsets -= np.einsum("ij,ij->i", offsets, n)[:, None] * n  # along the plane
        points = c + n * (margin + rng.uniform(0, 2, (len(guesses), 1))) + offsets
        box = along_world.structure.boxes[piece]
        clipped = np.clip(points, box.min_m, box.max_m)
        assert np.linalg.norm(points - clipped, axis=1).min() >= margin - 1e-9
    assert distance.shape == (len(guesses), proximity.pieces)


def test_closest_approach_is_the_least_of_a_dense_sampling():
    rng = np.random.default_rng(2)
    for _ in range(100):
        a0, a1, b0, b1 = rng.uniform(-5, 5, (4, 3))
        distance, fraction = closest_approach(a0, a1, b0, b1)
        s = np.linspace(0, 1, 20001)[:, None]
        sampled = np.linalg.norm((a0 + s * (a1 - a0)) - (b0 + s * (b1 - b0)), axis=1)
        assert distance <= sampled.min() + 1e-12
        assert distance >= sampled.min() - 1e-6
        assert abs(sampled[round(fraction * 20000)] - distance) < 1e-6


def test_segment_points_are_at_most_the_spacing_apart_and_include_both_ends():
    points = segment_points(np.zeros(3), np.array([1.0, 0.0, 0.0]), 0.3)
    assert np.array_equal(points[0], np.zeros(3)) and np.array_equal(points[-1], [1.0, 0, 0])
    assert np.diff(points[:, 0]).max() <= 0.3


def test_a_mesh_of_the_boxes_bodies_gives_the_same_pieces(along_world, tmp_path):
    """Each connected part of a mesh file is a piece, as each box is: the default bridge
    written as an STL has three, with the boxes' distances, closest points and normals, inside
    (watertight parts are signed) and out."""
    from mission.config.scenario import load_scenario
    from mission.world.model import World

    parts = [trimesh.creation.box(bounds=[b.min_m, b.max_m]) for b in along_world.structure.boxes]
    stl = tmp_path / "bridge.stl"
    trimesh.util.concatenate(parts).export(stl)
    overrides = {"world.structure.mesh_file": str(stl), "world.structure.primitives": []}
    mesh = StructureProximity(World(load_scenario("along", overrides)).structure)
    boxes = StructureProximity(along_world.structure)
    assert mesh.pieces == boxes.pieces == 3
    rng = np.random.default_rng(1)
    deck = along_world.structure.boxes[0]
    inside = rng.uniform(np.array(deck.min_m) + 0.01, np.array(deck.max_m) - 0.01, (50, 3))
    points = np.vstack([rng.uniform([-25, -20, 0], [25, 20, 20], (2000, 3)), inside])
    # the pieces in the order of their distance (a mesh's parts come in their own order)
    by_distance = [_by_distance(*p.closest(points)) for p in (mesh, boxes)]
    for ours, theirs in zip(*by_distance, strict=True):
        np.testing.assert_allclose(ours, theirs, atol=1e-9)


def _by_distance(distance, closest, normals):
    order = np.argsort(distance, axis=1)
    rows = np.arange(len(distance))[:, None]
    return distance[rows, order], closest[rows, order], normals[rows, order]


def test_a_watertight_part_is_solid_to_every_query_though_the_file_is_open(tmp_path):
    """A box beside an open plate: the file is not watertight, the box is; inside it both the
    structure's containment and the distances say so."""
    from mission.config.scenario import load_scenario
    from mission.world.model import World

    box = trimesh.creation.box(bounds=[(-2.0, -2.0, 0.0), (2.0, 2.0, 4.0)])
    plate = trimesh.Trimesh([[5, 0, 1], [9, 0, 1], [9, 4, 1]], [[0, 1, 2]])
    path = tmp_path / "mixed.stl"
    trimesh.util.concatenate([box, plate]).export(path)
    world = World(
        load_scenario(
            "along",
            {
                "world.structure.mesh_file": str(path),
                "world.structure.primitives": [],
                "world.zones": [],
            },
        )
    )
    proximity = StructureProximity(world.structure)
    inside, outside = np.array([[0.0, 0.0, 2.0]]), np.array([[7.0, 1.0, 3.0]])
    assert world.structure.contains(inside)[0] and not world.structure.contains(outside)[0]
    assert proximity.distance(inside)[0] == pytest.approx(-2.0)
    assert proximity.distance(outside)[0] == pytest.approx(2.0)
    assert world.placement_problem(inside[0]) == "inside the structure"
