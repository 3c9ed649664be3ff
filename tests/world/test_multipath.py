"""Multipath from geometry against closed forms: excess paths off the ground and a
wall, reflections that must not exist, the receiver's least squares, the code-tracking
envelope, and the open sky where nothing reflects within a chip."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from mission.config.errors import ScenarioError
from mission.config.scenario import load_scenario
from mission.config.settings import BoxPrimitive, StructureSettings
from mission.world.code_tracking import discriminator, echo_error_chips
from mission.world.gnss import least_squares_fix
from mission.world.model import World
from mission.world.reflections import Reflectors, check_reflecting_faces
from mission.world.structure import Structure, build_structure


def _structure(*boxes: tuple[tuple[float, float, float], tuple[float, float, float]]) -> Structure:
    primitives = [BoxPrimitive(f"b{i}", lo, hi) for i, (lo, hi) in enumerate(boxes)]
    return build_structure(StructureSettings(mesh_file=None, primitives=primitives))


def _directions(rng: np.random.Generator, n: int, min_el_deg: float = 5.0) -> np.ndarray:
    elevation = np.radians(rng.uniform(min_el_deg, 85.0, n))
    azimuth = np.radians(rng.uniform(0.0, 360.0, n))
    return np.column_stack(
        (
            np.sin(azimuth) * np.cos(elevation),
            np.cos(azimuth) * np.cos(elevation),
            np.sin(elevation),
        )
    )


FAR_AWAY = ((5000.0, 5000.0, 0.0), (5001.0, 5001.0, 1.0))  # a structure that reflects nothing here


def test_the_ground_bounce_is_2h_sin_e_over_random_geometries():
    rng = np.random.default_rng(1)
    structure = _structure(FAR_AWAY)
    for _ in range(50):
        point = np.array([rng.uniform(-50, 50), rng.uniform(-50, 50), rng.uniform(0.5, 30)])
        directions = _directions(rng, 12)
        reflectors = Reflectors(structure, directions, 0.5, 0.5, 0.0)
        paths = reflectors.paths(point[None])
        ground = paths.plane == reflectors.ground
        assert ground.sum() == 12  # every satellite above the horizon bounces off it
        expected = 2 * point[2] * directions[paths.satellite[ground], 2]
        assert np.abs(paths.excess_m[ground] - expected).max() < 1e-3
        assert np.abs(paths.specular_m[ground, 2]).max() < 1e-9  # on the ground


def test_a_wall_reflects_2d_cos_e_cos_daz_over_random_geometries():
    """The face x = 0 of a wall (normal pointing east, azimuth 90 degrees)."""
    rng = np.random.default_rng(2)
    wall = ((-1.0, -500.0, 0.0), (0.0, 500.0, 400.0))
    structure = _structure(wall)
    checked = 0
    for _ in range(50):
        d = rng.uniform(0.5, 40)
        point = np.array([d, rng.uniform(-50, 50), rng.uniform(1, 30)])
        elevation = np.radians(rng.uniform(5, 85, 10))
        azimuth = np.radians(rng.uniform(0, 360, 10))
        directions = np.column_stack(
            (
                np.sin(azimuth) * np.cos(elevation),
                np.cos(azimuth) * np.cos(elevation),
                np.sin(elevation),
            )
        )
        reflectors = Reflectors(structure, directions, 0.5, 0.0, 0.0)
        paths = reflectors.paths(point[None])
        off_wall = paths.plane != reflectors.ground
        cos_incidence = np.cos(elevation) * np.cos(azimuth - np.pi / 2)  # n . e
        reach = d / np.where(cos_incidence > 0, cos_incidence, np.inf)
        on_wall = (np.abs(point[1] + reach * directions[:, 1]) <= 500) & (
            point[2] + reach * directions[:, 2] <= 400
        )
        lit = (cos_incidence > 0) & on_wall  # the satellite on the wall's lit side
        assert set(paths.satellite[off_wall]) == set(np.flatnonzero(lit))
        sats = paths.satellite[off_wall]
        expected = 2 * d * np.cos(elevation[sats]) * np.cos(azimuth[sats] - np.pi / 2)
        assert np.abs(paths.excess_m[off_wall] - expected).max() < 1e-3
        checked += len(sats)
    assert checked > 100


def test_a_specular_point_off_the_face_or_a_blocked_leg_gives_no_reflection():
    """A 2 m x 2 m plate at x = 0: a receiver 5 m east and level with it sees satellites due
    east reflect (specular point on the plate); 3 m north of it, the point falls off the
    plate. A box between the receiver and the plate blocks the first leg."""
    plate = ((-0.2, -1.0, 4.0), (0.0, 1.0, 6.0))
    east_low = np.array([[np.cos(np.radians(5)), 0.0, np.sin(np.radians(5))]])
    reflectors = Reflectors(_structure(plate), east_low, 0.5, 0.0, 0.0)
    on = reflectors.paths(np.array([[5.0, 0.0, 5.0]]))
    assert (on.plane != reflectors.ground).sum() == 1
    assert on.specular_m[on.plane != reflectors.ground][0] == pytest.approx(
        [0.0, 0.0, 5.0 + 5.0 * np.tan(np.radians(5))], abs=1e-9
    )
    off = reflectors.paths(np.array([[5.0, 3.0, 5.0]]))
    assert (off.plane != reflectors.ground).sum() == 0
    blocker = ((2.0, -0.5, 4.0), (2.5, 0.5, 6.0))
    blocked = Reflectors(_structure(plate, blocker), east_low, 0.5, 0.0, 0.0)
    found = blocked.paths(np.array([[5.0, 0.0, 5.0]]))
    assert _plane(blocked, 0.0) not in found.plane  # only the blocker's own face reflects
    assert _plane(blocked, 2.5) in found.plane
    # a box over the specular point blocks the leg to the satellite instead
    roof = ((0.0, -1.0, 5.2), (4.0, 1.0, 5.4))
    steep = np.array([[np.cos(np.radians(30)), 0.0, np.sin(np.radians(30))]])
    open_plate = Reflectors(_structure(plate), steep, 0.5, 0.0, 0.0)
    covered = Reflectors(_structure(plate, roof), steep, 0.5, 0.0, 0.0)
    under_roof = np.array([[1.0, 0.0, 4.5]])
    assert _plane(open_plate, 0.0) in open_plate.paths(under_roof).plane
    assert _plane(covered, 0.0) not in covered.paths(under_roof).plane


def _plane(reflectors: Reflectors, x: float) -> int:
    """The index of the reflecting plane x = ``x``."""
    east = (np.abs(reflectors.normals - [1.0, 0.0, 0.0]).max(axis=1) < 1e-9) & (
        np.abs(reflectors.offsets - x) < 1e-9
    )
    return int(np.flatnonzero(east)[0])


def test_the_least_squares_fix_equals_numpys_lstsq():
    rng = np.random.default_rng(3)
    directions = _directions(rng, 11, 10.0)
    system = np.array([0] * 7 + [1] * 4)
    clocks = np.eye(2)[system]
    rows = np.hstack((-directions, clocks))
    for _ in range(20):
        bias = rng.uniform(-20, 20, 11)
        weight = rng.uniform(0.05, 1.0, 11)
        has_fix, error, cov = least_squares_fix(rows, system, weight[None], bias[None])
        root = np.sqrt(weight)
        by_hand = np.linalg.lstsq(rows * root[:, None], bias * root, rcond=None)[0]
        assert has_fix[0]
        assert np.abs(error[0] - by_hand[:3]).max() < 1e-3
        normal = rows.T @ (weight[:, None] * rows)
        assert np.allclose(cov[0], np.linalg.inv(normal)[:3, :3])
    # one constellation dropped: its clock is no unknown; four satellites fix three + one
    weight = np.r_[np.ones(4), np.zeros(7)]
    has_fix, error, _ = least_squares_fix(
        rows, system, weight[None], np.r_[np.ones(4), 9 * np.ones(7)][None]
    )
    assert has_fix[0] and np.abs(error[0]).max() < 1e-9  # a common bias is the clock's
    weight = np.r_[np.ones(3), np.zeros(8)]
    assert not least_squares_fix(rows, system, weight[None], np.zeros((1, 11)))[0][0]


def test_the_envelope_is_the_discriminators_root():
    rng = np.random.default_rng(4)
    for _ in range(300):
        a, tau, d = rng.uniform(0, 0.95), rng.uniform(0, 1.6), rng.uniform(0.02, 1.0)
        expected = float(echo_error_chips(np.array(a), np.array(tau), d))
        grid = np.linspace(-d / 2, 1.2, 24001)
        values = discriminator(grid, a, tau, d)
        crossing = np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:]))
        roots = grid[crossing] if len(crossing) else np.array([0.0])
        assert np.min(np.abs(roots - expected)) < 1e-3 + 1e-4
    # the plateau of a narrow correlator: a d / 2 for delays well inside a chip
    assert echo_error_chips(np.array(0.5), np.array(0.5), 0.1) == pytest.approx(0.025)
    assert echo_error_chips(np.array(0.5), np.array(1.2), 0.1) == 0.0


def _geometry_world(**signal) -> World:
    scenario = load_scenario("river")
    gnss = dataclasses.replace(scenario.world.gnss, **signal)
    return World(
        dataclasses.replace(scenario, world=dataclasses.replace(scenario.world, gnss=gnss))
    )


def test_high_above_open_ground_the_fix_is_todays_draw_for_draw():
    """2 km up, every ground echo is later than a chip plus half the spacing (GLONASS's
    586 m chip included), so even a code receiver's error is the noise, and the same draws
    give today's fix."""
    world = _geometry_world(solution="code")
    point = np.array([0.0, -15.0, 2000.0])
    solution = world.receiver.solve(point[None])
    assert solution.carrier_fixed[0] == np.False_ and np.abs(solution.position_error_m).max() < 1e-9
    fix = world.receiver.sample_fix(point, np.random.default_rng(7))
    today = world.gnss.sample_fix(point, np.random.default_rng(7))
    assert np.abs(fix.position_m - today.position_m).max() < 1e-9
    assert fix.hdop == pytest.approx(today.hdop) and fix.n_visible == today.n_visible


def test_nlos_under_the_deck_puts_the_fix_at_the_waters_mirror_image():
    """Deep under the deck every tracked signal bounced off the water: each is 2 h sin(e)
    late, which is exactly the range from the receiver's image 2 h below it."""
    world = _geometry_world()
    solution = world.receiver.solve(np.array([[0.0, 0.0, 7.0]]))
    assert solution.has_fix[0] and solution.reflected[0].sum() == solution.n_used[0] >= 5
    assert solution.position_error_m[0] == pytest.approx([0.0, 0.0, -14.0], abs=1e-6)


def test_the_river_field_has_no_nan_and_no_fix_short_of_its_unknowns():
    world = _geometry_world()
    centers = world.map_grid().centers().reshape(-1, 3)[::7]
    solution = world.receiver.solve(centers)
    fixed = solution.has_fix
    assert np.isfinite(solution.position_error_m[fixed]).all()
    assert np.isfinite(solution.cov_geom[fixed]).all()
    system = world.sky.constellation_index()
    clocks = np.stack([(solution.tracked[:, system == k]).any(axis=1) for k in range(2)], axis=1)
    assert (solution.n_used[fixed] >= 3 + clocks[fixed].sum(axis=1)).all()
    assert np.isnan(solution.position_error_m[~fixed]).all()


def test_an_rtk_receiver_keeps_its_fix_until_it_tracks_a_reflection():
    world = _geometry_world()
    open_sky = world.receiver.solve(np.array([[0.0, -19.0, 15.0]]))
    assert open_sky.carrier_fixed[0] and not open_sky.reflected[0].any()
    assert np.abs(open_sky.position_error_m[0]).max() < 1e-9
    edge = world.receiver.solve(np.array([[-11.0, -6.5, 7.8]]))
    assert not edge.carrier_fixed[0] and edge.reflected[0].any()
    assert np.linalg.norm(edge.position_error_m[0]) > 0.5


def test_a_triangle_without_a_normal_is_refused(tmp_path):
    mesh = tmp_path / "flat.obj"
    mesh.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n", encoding="utf-8")
    structure = Structure(
        np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0]], dtype=float),
        np.array([[0, 1, 2], [0, 1, 3]]),
        [],
    )
    with pytest.raises(ScenarioError) as refused:
        check_reflecting_faces(structure, str(mesh))
    assert "world.structure.mesh_file" in str(refused.value) and "face 1" in str(refused.value)


@pytest.mark.parametrize(
    ("override", "field"),
    [
        ({"world.gnss.amplitude.water": 1.2}, "world.gnss.amplitude.water"),
        ({"world.gnss.amplitude.concrete": -0.1}, "world.gnss.amplitude.concrete"),
        ({"world.gnss.correlator_spacing_chips": -0.1}, "world.gnss.correlator_spacing_chips"),
        ({"world.gnss.cn0_floor_dbhz": 50.0}, "world.gnss.cn0_floor_dbhz"),
        ({"world.gnss.multipath": "rays"}, "world.gnss.multipath"),
        ({"world.gnss.multipath": "geometry"}, "world.gnss.multipath"),  # along has a zone
    ],
)
def test_bad_signal_settings_are_refused_naming_the_field(override, field):
    with pytest.raises(ScenarioError) as refused:
        load_scenario("along", override)
    assert field in str(refused.value)


def test_the_ground_station_never_gets_the_multipath_model():
    """Not the model, nor what would rebuild it: the river's water, its receiver, its
    constants are the defaults' in the known world's scenario."""
    river = load_scenario(
        "river", {"world.gnss.amplitude.concrete": 0.3, "world.gnss.solution": "code"}
    )
    world = World(river)
    known = world.known()
    assert world.receiver is not None and not hasattr(known, "receiver")
    assert known.scenario.world.gnss == load_scenario("along").world.gnss  # the defaults
    assert known.scenario.world.gnss.ground_surface == "ground" and not known.scenario.world.zones


def test_a_fix_is_the_same_for_the_same_seed_and_place_one_point_or_many():
    world = _geometry_world()
    points = np.array([[-11.0, -6.5, 7.8], [0.0, 0.0, 7.0], [5.0, -7.5, 8.5], [0.0, -19.0, 15.0]])
    together = world.receiver.solve(points)
    for k, point in enumerate(points):
        alone = world.receiver.solve(point[None])
        assert np.array_equal(alone.position_error_m[0], together.position_error_m[k])
        assert np.array_equal(alone.range_error_m[0], together.range_error_m[k])
    first = world.gnss_fix(points[0], np.random.default_rng(11))
    again = world.gnss_fix(points[0], np.random.default_rng(11))
    assert np.array_equal(first.position_m, again.position_m) and first.solution == again.solution


def test_a_finely_meshed_wall_reflects_as_one_face():
    """A 20 m x 20 m wall at x = 0 of 800 triangles, split into planes of at most 16 for the
    face test: each satellite on its lit side reflects once, 2 d cos e cos dAz later."""
    n = 20
    y, z = np.meshgrid(np.linspace(-10, 10, n + 1), np.linspace(0, 20, n + 1), indexing="ij")
    vertices = np.column_stack((np.zeros(y.size), y.ravel(), z.ravel()))
    index = np.arange(y.size).reshape(n + 1, n + 1)
    quads = [(index[i, j], index[i + 1, j], index[i + 1, j + 1], index[i, j + 1])
             for i in range(n) for j in range(n)]  # fmt: skip
    faces = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))])
    structure = Structure(vertices, faces, [])
    directions = _directions(np.random.default_rng(5), 40)
    reflectors = Reflectors(structure, directions, 0.5, 0.0, 0.0)
    assert len(reflectors.normals) - 1 == 800 // 16  # the wall in planes of 16, and the ground
    point = np.array([[3.0, 0.3, 7.1]])
    paths = reflectors.paths(point)
    wall = paths.plane != reflectors.ground
    sats = paths.satellite[wall]
    assert len(sats) == len(set(sats))  # once each
    reach = 3.0 / directions[:, 0]
    on = (directions[:, 0] > 0) & (np.abs(0.3 + reach * directions[:, 1]) <= 10)
    on &= (7.1 + reach * directions[:, 2] >= 0) & (7.1 + reach * directions[:, 2] <= 20)
    assert set(sats) == set(np.flatnonzero(on))
    assert np.allclose(paths.excess_m[wall], 2 * 3.0 * directions[sats, 0], atol=1e-6)
