"""The surfaces above and below points: the deck's underside, the deck's top, the ground, from
the box primitives in closed form and from a mesh file by ray casting (the same answers)."""

from __future__ import annotations

import numpy as np
import trimesh

from mission.config.settings import StructureSettings
from mission.world.structure import build_structure
from mission.world.surfaces import NONE_ABOVE_M, VerticalSurfaces

POINTS = np.array(
    [
        [0.0, 0.0, 7.0],  # under the deck (underside 8 m, top 9 m)
        [0.0, 4.9, 2.0],  # under it, near its edge
        [0.0, 5.1, 7.0],  # just outside its footprint: open sky
        [3.0, -2.0, 12.0],  # over it
        [-16.0, 4.0, 5.0],  # beside a pier, under the deck
    ]
)
ABOVE = [8.0, 8.0, NONE_ABOVE_M, NONE_ABOVE_M, 8.0]
BELOW = [0.0, 0.0, 0.0, 9.0, 0.0]


def test_the_boxes_give_the_deck_above_and_the_ground_or_deck_below(along_world):
    above, below = VerticalSurfaces(along_world.structure).heights(POINTS)
    np.testing.assert_array_equal(above, ABOVE)
    np.testing.assert_array_equal(below, BELOW)


def test_a_mesh_file_of_the_same_deck_gives_the_same_heights(tmp_path):
    deck = trimesh.creation.box(extents=[40.0, 10.0, 1.0])
    deck.apply_translation([0.0, 0.0, 8.5])
    path = tmp_path / "deck.stl"
    deck.export(path)
    structure = build_structure(StructureSettings(mesh_file=str(path), primitives=[]))
    above, below = VerticalSurfaces(structure).heights(POINTS)
    np.testing.assert_allclose(above, ABOVE, atol=1e-9)
    np.testing.assert_allclose(below, BELOW, atol=1e-9)
