"""GNSS model against the published DOP figures, hand geometry and sampling statistics."""

from __future__ import annotations

import numpy as np
import pytest

from mission.config.scenario import load_scenario
from mission.world.model import World

OPEN_SKY_POINT = np.array([0.0, -15.0, 8.0])


def _world(write_scenario, body: str) -> World:
    return World(load_scenario(str(write_scenario(body))))


@pytest.mark.parametrize(
    ("constellations", "n_sats", "pdop", "hdop", "vdop"),
    [("[G, R]", 15, 1.44, 0.73, 1.24), ("[G]", 9, 1.89, 0.97, 1.63), ("[R]", 6, 2.86, 1.45, 2.46)],
)
def test_open_sky_dop_matches_published_cross_check(
    write_scenario, constellations, n_sats, pdop, hdop, vdop
):
    """03:00Z, 10 deg mask: the table in the data README (independent computation)."""
    world = _world(write_scenario, f"sky: {{constellations: {constellations}}}\n")
    geometry = world.gnss.geometry(OPEN_SKY_POINT[None])
    assert int(geometry.n_visible[0]) == n_sats
    assert geometry.pdop[0] == pytest.approx(pdop, abs=0.01)
    assert geometry.hdop[0] == pytest.approx(hdop, abs=0.01)
    assert geometry.vdop[0] == pytest.approx(vdop, abs=0.01)


def test_open_sky_sigma_is_rtk_level(along_world):
    """sqrt(tr Sigma_GNSS) = sigma_UERE * PDOP, about the paper's 0.15 m."""
    has_fix, sigma = along_world.gnss.sigma_gnss(OPEN_SKY_POINT[None])
    assert has_fix[0]
    assert np.sqrt(np.trace(sigma[0])) == pytest.approx(0.10 * 1.4396, abs=1e-3)
    assert along_world.gnss.sigma0(OPEN_SKY_POINT[None])[0] == pytest.approx(0.144, abs=1e-3)


def _slab_hit(origin: np.ndarray, direction: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> bool:
    """Ray-box intersection by the slab method, written independently of trimesh."""
    t_near, t_far = 0.0, np.inf
    for axis in range(3):
        if abs(direction[axis]) < 1e-12:
            if not lo[axis] <= origin[axis] <= hi[axis]:
                return False
            continue
        t1 = (lo[axis] - origin[axis]) / direction[axis]
        t2 = (hi[axis] - origin[axis]) / direction[axis]
        t_near = max(t_near, min(t1, t2))
        t_far = min(t_far, max(t1, t2))
    return t_near <= t_far


def test_plate_blocks_exactly_the_satellites_whose_rays_cross_it(write_scenario):
    plate_lo, plate_hi = np.array([-3.0, -1.0, 5.0]), np.array([6.0, 4.0, 5.2])
    world = _world(
        write_scenario,
        f"""
        world:
          structure:
            primitives:
              - {{name: plate, min_m: {plate_lo.tolist()}, max_m: {plate_hi.tolist()}}}
        """,
    )
    point = np.array([0.5, 0.0, 2.0])
    visible = world.gnss.visibility(point[None])[0]
    directions = world.sky.directions_enu
    expected_blocked = np.array([_slab_hit(point, d, plate_lo, plate_hi) for d in directions])
    above = world.sky.above_mask
    assert 0 < expected_blocked[above].sum() < above.sum(), "the test needs a partial shadow"
    np.testing.assert_array_equal(visible[above], ~expected_blocked[above])
    assert not np.any(visible[~above]), "satellites below the mask are never used"


def test_point_under_the_deck_has_no_fix(along_world):
    geometry = along_world.gnss.geometry(np.array([[0.0, 0.0, 6.0], [0.0, -4.0, 6.0]]))
    assert not geometry.has_fix[0]
    open_pdop = along_world.gnss.geometry(OPEN_SKY_POINT[None]).pdop[0]
    # Near the deck edge a fix may survive, but far worse than in the open.
    assert not geometry.has_fix[1] or geometry.pdop[1] > 2 * open_pdop
    points = np.array([[0.0, 0.0, 6.0], OPEN_SKY_POINT, [0.0, -4.0, 6.0]])
    np.testing.assert_array_equal(
        along_world.gnss.has_fix(points), along_world.gnss.geometry(points).has_fix
    )
    assert along_world.gnss.has_fix(points).tolist()[:2] == [False, True]


def test_fix_noise_has_sigma_gnss_covariance(along_world):
    rng = np.random.default_rng(7)
    point = np.array([0.0, -7.0, 7.0])
    has_fix, sigma = along_world.gnss.sigma_gnss(point[None])
    assert has_fix[0]
    errors = np.array(
        [along_world.gnss.sample_fix(point, rng).position_m - point for _ in range(4000)]
    )
    whitened = np.linalg.solve(np.linalg.cholesky(sigma[0]), errors.T).T
    np.testing.assert_allclose(whitened.mean(axis=0), 0.0, atol=4 / np.sqrt(4000))
    np.testing.assert_allclose(np.cov(whitened.T), np.eye(3), atol=0.08)


def test_zone_offset_applies_inside_the_zone_only(along_world):
    zone = along_world.scenario.world.zones[0]
    lo, hi = np.array(zone.min_m), np.array(zone.max_m)
    inside = (lo + hi) / 2
    outside = [inside + [0, 0, 3.0], np.array([lo[0] - 0.01, inside[1], inside[2]]), np.zeros(3)]
    offsets = along_world.zone_offset(np.vstack([inside, *outside]))
    np.testing.assert_array_equal(offsets[0], zone.offset_m)
    np.testing.assert_array_equal(offsets[1:], 0.0)
    rng = np.random.default_rng(3)
    fixes = np.array(
        [along_world.gnss.sample_fix(inside, rng, offsets[0]).position_m for _ in range(400)]
    )
    np.testing.assert_allclose(fixes.mean(axis=0), inside + zone.offset_m, atol=0.05)


def test_one_point_and_many_points_find_the_same_zone(along_world):
    """A vehicle asks one point a step (a plain-float path); batches use numpy. Points on the
    faces count as inside, NaN as outside, either way."""
    zone = along_world.scenario.world.zones[0]
    lo, hi = np.array(zone.min_m), np.array(zone.max_m)
    rng = np.random.default_rng(4)
    points = np.vstack(
        [
            rng.uniform([-25, -20, 0], [25, 20, 20], (3000, 3)),
            rng.uniform(lo - 0.5, hi + 0.5, (3000, 3)),
            [lo, hi, np.nextafter(lo, -np.inf), [np.nan, lo[1], lo[2]]],
        ]
    )
    batch = along_world.zone_offset(points)
    one_by_one = np.vstack([along_world.zone_offset(point[None]) for point in points])
    np.testing.assert_array_equal(one_by_one, batch)
    assert 500 < (batch[:, 0] != 0).sum() < 3000  # both kinds, many of each
    np.testing.assert_array_equal(batch[-4:-2], [zone.offset_m] * 2)
    np.testing.assert_array_equal(batch[-2:], 0.0)


def test_reported_accuracy_ignores_the_multipath_offset(along_world):
    """A receiver does not know its bias: reported DOP is the same with or without offset."""
    rng = np.random.default_rng(1)
    point = np.array([-7.5, -9.0, 8.0])
    plain = along_world.gnss.sample_fix(point, rng)
    biased = along_world.gnss.sample_fix(point, rng, np.array([1.0, 0, 0]))
    assert plain.hdop == biased.hdop and plain.vdop == biased.vdop
    np.testing.assert_array_equal(plain.covariance_m2, biased.covariance_m2)


def test_sigma0_map_open_sky_and_capped_under_the_deck(along_world):
    sigma0 = along_world.sigma0_map()
    assert sigma0.grid.n_voxels >= 10_000
    grid = sigma0.grid
    open_index = tuple(grid.index_of(np.array([[0.0, -18.0, 15.0]]))[0])
    under_index = tuple(grid.index_of(np.array([[0.0, 0.0, 4.0]]))[0])
    assert sigma0.sigma_m[open_index] == pytest.approx(0.144, abs=1e-3)
    assert sigma0.sigma_m[under_index] == along_world.scenario.map.no_fix_sigma_m
    assert not sigma0.has_fix[under_index]
    assert np.all(sigma0.sigma_m <= along_world.scenario.map.no_fix_sigma_m)


def _points_around_the_bridge(n: int, seed: int = 3) -> np.ndarray:
    """Open sky, beside the piers and under the deck (every kind of visibility mask)."""
    rng = np.random.default_rng(seed)
    return np.column_stack(
        [rng.uniform(-30, 30, n), rng.uniform(-20, 20, n), rng.uniform(0.5, 12, n)]
    )


def test_fixes_are_the_same_with_remembered_geometry(along_world, monkeypatch):
    """Fix geometry remembered per visibility mask (and the memory emptied when full) gives
    the fixes that computing it afresh for every fix gives, bit for bit."""
    from mission.world import gnss

    points = _points_around_the_bridge(300)
    fresh = World(along_world.scenario).gnss
    remembered = World(along_world.scenario).gnss
    monkeypatch.setattr(gnss, "_MAX_REMEMBERED_MASKS", 5)  # exercise the emptying too

    def afresh(model, visible):
        cov = gnss._single_point_cov_geom(
            model._rows[visible], model.sky.constellation_index()[visible]
        )
        return cov, gnss.cholesky_or_none(cov) if cov is not None else None

    monkeypatch.setattr(fresh, "_fix_geometry", lambda visible: afresh(fresh, visible))
    rng_a, rng_b = np.random.default_rng(9), np.random.default_rng(9)
    with_fix = 0
    for point in np.vstack([points, points]):  # the second pass finds masks remembered
        a, b = fresh.sample_fix(point, rng_a), remembered.sample_fix(point, rng_b)
        assert (a.has_fix, a.n_visible, a.hdop, a.vdop) == (b.has_fix, b.n_visible, b.hdop, b.vdop)
        if a.has_fix:
            with_fix += 1
            assert np.array_equal(a.position_m, b.position_m)
            assert np.array_equal(a.covariance_m2, b.covariance_m2)
    assert 0 < with_fix < 600  # both kinds of point were drawn
    assert 0 < len(remembered._fix_geometry_by_mask) <= 5


def _every_row_computed(model, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(has_fix, cov_geom) with no memory and no grouping: the batched formula on every row."""
    from mission.world import gnss

    visible = model.visibility(points)
    return gnss._covariance_from_visibility(visible, model._rows, model.sky.constellation_index())


def test_a_few_points_geometry_equals_the_batched_computation(along_world, monkeypatch):
    """Sigma_GNSS of a cycle's few fixes, looked up per mask, and of many points, grouped by
    mask, equal the batched computation on every row (a row does not depend on the rows
    beside it)."""
    from mission.world import gnss

    points = _points_around_the_bridge(240, seed=4)
    model = World(along_world.scenario).gnss
    monkeypatch.setattr(gnss, "_MAX_REMEMBERED_MASKS", 7)
    assert len(points) > gnss._MEMO_MAX_POINTS  # so this call is the grouped one
    has_fix_all, cov_all = _every_row_computed(model, points)
    sigma_all = along_world.scenario.gnss.sigma_uere_m**2 * cov_all
    has_fix, sigma = model.sigma_gnss(points)
    assert np.array_equal(has_fix, has_fix_all)
    assert np.array_equal(sigma, sigma_all, equal_nan=True)
    for start in range(0, len(points), 3):
        has_fix, sigma = model.sigma_gnss(points[start : start + 3])
        assert np.array_equal(has_fix, has_fix_all[start : start + 3])
        assert np.array_equal(sigma, sigma_all[start : start + 3], equal_nan=True)
    assert 0 < has_fix_all.sum() < len(points)


def test_the_map_grouped_by_mask_equals_every_voxel_computed(along_world):
    model = World(along_world.scenario).gnss
    centers = along_world.map_grid().centers().reshape(-1, 3)
    geometry = model.geometry(centers)
    has_fix, cov = _every_row_computed(model, centers)
    assert np.array_equal(geometry.has_fix, has_fix)
    assert np.array_equal(geometry.cov_geom, cov, equal_nan=True)
    assert len(np.unique(geometry.visible, axis=0)) < len(centers) / 50  # few masks, many voxels
