"""Routes around the structure (:mod:`mission.world.routes`) on Along's bridge: from under the
deck to above it, kept off the structure by the margin and off other UAVs where asked."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from mission.config.scenario import load_scenario
from mission.world.model import KnownWorld
from mission.world.proximity import StructureProximity
from mission.world.routes import Obstacles, RouteMap

MARGIN_M = 1.25
UNDER, ABOVE = np.array([-8.0, -1.0, 6.0]), np.array([-8.0, 1.0, 11.0])  # the deck: z 8..9


@pytest.fixture(scope="module")
def routes() -> RouteMap:
    world = KnownWorld(load_scenario("along"))
    return RouteMap(world.map_grid(), StructureProximity(world.structure), MARGIN_M)


def _sampled(route: np.ndarray, spacing: float = 0.05) -> np.ndarray:
    return np.vstack(
        [a + (b - a) * np.linspace(0, 1, int(np.linalg.norm(b - a) / spacing) + 2)[:, None]
         for a, b in itertools.pairwise(route)]
    )  # fmt: skip


def _length(route: np.ndarray) -> float:
    return float(np.sum(np.linalg.norm(np.diff(route, axis=0), axis=1)))


def test_a_route_from_under_the_deck_to_above_it_goes_round_its_edge(routes):
    route = routes.route(UNDER, ABOVE)
    assert route is not None
    assert np.array_equal(route[0], UNDER) and np.array_equal(route[-1], ABOVE)
    clearance = routes.proximity.clearance(_sampled(route))
    # the ends are closer than the margin; between them it is kept (to a voxel's rounding)
    assert clearance.min() > 0.9 and len(route) >= 3
    # round the south or north edge: the deck is 10 m wide, so at least out to |y| > 5
    assert np.abs(route[:, 1]).max() > 5.0
    straight = np.linalg.norm(ABOVE - UNDER)
    assert straight < _length(route) <= routes.lengths(UNDER, ABOVE)[0, 0] + 1e-6


def test_an_open_straight_way_is_taken_as_it_is(routes):
    start, goal = np.array([-8.0, -12.0, 3.0]), np.array([8.0, -12.0, 3.0])
    np.testing.assert_array_equal(routes.route(start, goal), [start, goal])


def test_a_route_keeps_off_another_uav(routes):
    start, goal = np.array([-8.0, -12.0, 3.0]), np.array([8.0, -12.0, 3.0])
    other = np.array([[0.0, -12.0, 3.0]])
    route = routes.route(start, goal, other, 3.5)
    assert len(route) > 2
    assert Obstacles(other, 3.5 - 0.05).covers(_sampled(route)).sum() == 0
    assert routes.route(start, goal, other, 0.0).tolist() == [start.tolist(), goal.tolist()]


def test_a_route_keeps_to_open_sky_where_it_can():
    """South of the deck to north of it, both in the open: not through the deck's shadow,
    where no fix is, nor where fixes are poor (low under the deck, where the sky's sides
    still give good ones, or round)."""
    from mission.world.routes import route_map

    world = KnownWorld(load_scenario("along"))
    routes = route_map(world)
    south, north = np.array([-8.0, -8.0, 6.0]), np.array([-8.0, 8.0, 6.0])
    assert routes.cost_at(np.vstack([south, north])).max() == 1.0
    route = routes.route(south, north)
    assert routes.cost_at(_sampled(route)).max() == 1.0  # sigma_0 <= 0.3 m all the way
    flat = RouteMap(routes.grid, routes.proximity, routes.margin_m)  # at any cost: under it
    assert routes.cost_at(_sampled(flat.route(south, north))).max() == 100.0


def test_the_structure_in_the_way_is_what_the_distances_say(routes):
    """The quick box test equals the structure's distance at the same samples."""
    rng = np.random.default_rng(1)
    for _ in range(300):
        a, b = rng.uniform([-25, -20, 0], [25, 20, 20], (2, 3))
        count = max(2, int(np.ceil(np.linalg.norm(b - a) / 0.25)) + 1)
        points = a + (b - a) * np.linspace(0.0, 1.0, count)[:, None]
        near = bool(np.any(routes.proximity.distance(points) < 0.5))
        assert routes.structure_between(a, b, 0.5) == near
