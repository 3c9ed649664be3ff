"""A vehicle's GPS_RAW_INT where the multipath comes from geometry: what such a
receiver reports (the satellites it used, its solution's fix type, accuracy from the geometry
it used), and never its bias; SIM_MP_SCALE scales the bias."""

from __future__ import annotations

import numpy as np
import pytest

from mission.config.scenario import load_scenario
from mission.world.frames import GeodeticFrame
from mission.world.model import World
from vehicle_sim.mavlink import telemetry

EDGE = np.array([-11.0, -6.5, 7.8])  # beside the deck's south edge: a reflection tracked
OPEN = np.array([0.0, -19.0, 15.0])  # open sky: carrier-fixed


@pytest.fixture(scope="module")
def river() -> World:
    return World(load_scenario("river"))


def _message(world: World, point: np.ndarray, scale: float = 1.0):
    fix = world.gnss_fix(point, np.random.default_rng(3), 0.1, scale)
    frame = GeodeticFrame(world.scenario.world.anchor)
    return fix, telemetry.gps_raw_int(fix, frame, 1_000_000, 0.1), frame


def test_a_float_fix_says_so_with_the_satellites_and_geometry_it_used(river):
    solution = river.receiver.solve(EDGE[None])
    fix, message, frame = _message(river, EDGE)
    assert message.fix_type == 5 and fix.solution == "rtk-float"  # GPS_FIX_TYPE_RTK_FLOAT
    assert message.satellites_visible == int(solution.n_used[0])
    hdop = np.sqrt(solution.cov_geom[0, 0, 0] + solution.cov_geom[0, 1, 1])
    assert message.eph == round(hdop * 100) and message.h_acc == round(0.1 * hdop * 1000)
    reported = frame.to_enu(message.lat / 1e7, message.lon / 1e7, message.alt / 1000)
    bias = solution.position_error_m[0]
    assert np.linalg.norm(reported - (EDGE + bias)) < 0.6  # the bias and noise of 0.1 m x DOP
    assert message.h_acc < 1000 * np.hypot(*bias[:2])  # the accuracy does not know the bias


def test_open_sky_is_carrier_fixed_and_the_scale_moves_only_the_bias(river):
    assert _message(river, OPEN)[1].fix_type == 6  # GPS_FIX_TYPE_RTK_FIXED
    biased, _, _ = _message(river, EDGE, 1.0)
    unbiased, _, _ = _message(river, EDGE, 0.0)
    bias = river.receiver.solve(EDGE[None]).position_error_m[0]
    assert biased.position_m - unbiased.position_m == pytest.approx(bias, abs=1e-9)
