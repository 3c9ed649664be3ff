"""Each failure kind on the messages it changes: DELAYED gives the fix of a second earlier,
GARBAGE anywhere on Earth, the camera's WRONG turns the relative vector 0.1 rad, and OK
restores the healthy stream exactly."""

from __future__ import annotations

import math

import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from vehicle_sim.sensors import failures
from vehicle_sim.sensors.failures import SensorFailures

GPS_ID = mavlink2.MAVLINK_MSG_ID_GPS_RAW_INT
CAMERA_ID = mavlink2.MAVLINK_MSG_ID_LANDING_TARGET


def _fix(step: int):
    return mavlink2.MAVLink_gps_raw_int_message(
        step * 500_000, 3, 350_000_000 + step, 1_390_000_000, 10_000, 100, 100, 0, 0, 8
    )


def _sighting(north: float, east: float):
    angle = math.atan2(east, north)
    return mavlink2.MAVLink_landing_target_message(
        0, 1, mavlink2.MAV_FRAME_LOCAL_OFFSET_NED, angle, 0, 5, 0, 0, north, east, 0,
        [1, 0, 0, 0], mavlink2.LANDING_TARGET_TYPE_VISION_OTHER, 1,
    )  # fmt: skip


def test_delayed_gives_the_fix_of_a_second_before_and_ok_restores_the_stream():
    sensors = SensorFailures(seed=0, sensor_hz=2.0)
    for step in range(5):
        sensors.filter(GPS_ID, _fix(step))
    assert sensors.inject(failures.GPS, failures.DELAYED)
    late = sensors.filter(GPS_ID, _fix(5))
    assert late.time_usec == _fix(3).time_usec and late.lat == _fix(3).lat  # 1 s = 2 fixes
    assert sensors.inject(failures.GPS, failures.OK)
    assert sensors.filter(GPS_ID, _fix(6)).lat == _fix(6).lat


def test_garbage_is_anywhere_on_earth_and_reproducible():
    def garbage(seed: int) -> list[tuple[int, int]]:
        sensors = SensorFailures(seed, 2.0)
        sensors.inject(failures.GPS, failures.GARBAGE)
        return [(m.lat, m.lon) for m in (sensors.filter(GPS_ID, _fix(s)) for s in range(20))]

    values = garbage(1)
    assert values == garbage(1) and values != garbage(2)
    assert all(abs(lat) <= 900_000_000 and abs(lon) <= 1_800_000_000 for lat, lon in values)
    assert len(set(values)) == 20


def test_a_wrong_camera_turns_the_sighting_and_a_stuck_one_repeats_it():
    sensors = SensorFailures(0, 2.0)
    sensors.filter(CAMERA_ID, _sighting(3.0, 4.0))
    assert sensors.inject(failures.CAMERA, failures.WRONG)
    turned = sensors.filter(CAMERA_ID, _sighting(3.0, 4.0))
    assert math.hypot(turned.x, turned.y) == pytest.approx(5.0)
    assert math.atan2(turned.y, turned.x) - math.atan2(4.0, 3.0) == pytest.approx(0.1)
    assert sensors.inject(failures.CAMERA, failures.STUCK)
    stuck = sensors.filter(CAMERA_ID, _sighting(-1.0, 2.0))
    assert (stuck.x, stuck.y) == (3.0, 4.0)  # the last healthy sighting
    assert not sensors.inject(failures.CAMERA, failures.DELAYED)  # not offered
    assert sensors.filter(GPS_ID, _fix(0)).lat == _fix(0).lat  # the GNSS is untouched
