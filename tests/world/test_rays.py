"""The Embree occlusion engine agrees with trimesh's own ray tracer."""

from __future__ import annotations

import numpy as np
import pytest

from mission.world.rays import EmbreeRays, TrimeshRays
from tests.extras import embree_available


def test_embree_and_trimesh_agree_on_rays_and_segments(along_world):
    if not embree_available():
        pytest.skip("embreex has no wheel for this machine")
    structure = along_world.structure
    embree = EmbreeRays(structure.vertices, structure.faces)
    reference = TrimeshRays(structure.mesh)
    rng = np.random.default_rng(4)
    origins = rng.uniform([-25, -12, 0.5], [25, 12, 15], (3000, 3))
    directions = rng.normal(size=(3000, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    lengths = rng.uniform(0.5, 30, 3000)
    rays_embree = embree.occluded(origins, directions)
    assert 0.1 < rays_embree.mean() < 0.9, "a mix of hits and misses"
    np.testing.assert_array_equal(rays_embree, reference.occluded(origins, directions))
    np.testing.assert_array_equal(
        embree.occluded(origins, directions, lengths),
        reference.occluded(origins, directions, lengths),
    )


def test_the_fallback_engine_gives_the_same_gnss_visibility(along_world):
    """With trimesh's tracer the GNSS visibility is the same as with the default engine."""
    from mission.world.structure import Structure

    structure = along_world.structure
    fallback = Structure(structure.vertices, structure.faces, structure.boxes)
    fallback.rays = TrimeshRays(structure.mesh)
    directions = along_world.sky.directions_enu
    points = np.array([[0.0, -7.0, 7.0], [0.0, 0.0, 6.0], [10.0, -6.0, 3.0]])
    origins = np.repeat(points, len(directions), axis=0)
    tiled = np.tile(directions, (len(points), 1))
    np.testing.assert_array_equal(
        structure.rays_blocked(origins, tiled), fallback.rays_blocked(origins, tiled)
    )


def test_box_triangles_match_trimesh_boxes():
    """Our triangulated box equals trimesh's: same corners, closed, outward, same volume."""
    import trimesh

    from mission.config.settings import BoxPrimitive
    from mission.world.structure import _box_triangles

    box = BoxPrimitive(name="b", min_m=(-1.0, 2.0, 0.5), max_m=(3.0, 2.5, 4.0))
    vertices, faces = _box_triangles(box)
    ours = trimesh.Trimesh(vertices, faces, process=False)
    theirs = trimesh.creation.box(extents=[4.0, 0.5, 3.5])
    theirs.apply_translation([1.0, 2.25, 2.25])
    assert ours.is_watertight and ours.is_winding_consistent
    assert ours.volume == pytest.approx(theirs.volume) == pytest.approx(4.0 * 0.5 * 3.5)
    np.testing.assert_allclose(np.unique(ours.vertices, axis=0), np.unique(theirs.vertices, axis=0))
    np.testing.assert_allclose(ours.area_faces.sum(), theirs.area_faces.sum())


@pytest.mark.slow
def test_a_world_of_boxes_loads_without_trimesh():
    """The vehicles and the ground station start without importing trimesh (start-up time)."""
    import subprocess
    import sys

    code = (
        "import sys; from mission.world.model import World; w = World.load('along'); "
        "w.sigma0_map(); print('trimesh' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
