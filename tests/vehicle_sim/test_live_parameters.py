"""A parameter set live changes what the vehicle does (in-process vehicles): the failsafe trips
after FS_GCS_TIMEOUT as set, not as the scenario had it."""

from __future__ import annotations

import contextlib
import socket

import numpy as np
import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.link.mavlink_udp import MavlinkCodec, UdpEndpoint
from mission.link.vehicle_identity import VehicleIdentity
from vehicle_sim.mavlink import modes
from vehicle_sim.vehicle import Vehicle


def _failsafe_after_s(world, timeout_s: float | None) -> float:
    """Simulated seconds from the last setpoint to the failsafe's STATUSTEXT."""
    sent: list = []
    home = np.array([0.0, -10.0, 7.0])
    vehicle = Vehicle(
        VehicleIdentity.parse("support-1"), world.scenario, world, home, 0, sent.append
    )
    if timeout_s is not None:
        vehicle.params.handle(
            mavlink2.MAVLink_param_set_message(
                2, 1, b"FS_GCS_TIMEOUT", timeout_s, mavlink2.MAV_PARAM_TYPE_REAL32
            )
        )
    vehicle.change_mode(modes.GUIDED)
    vehicle.arm(True)
    sent.clear()
    while vehicle.sim_time_s < 60.0:
        vehicle.step()
        if any(m.get_type() == "STATUSTEXT" and "Failsafe" in m.text for m in sent):
            return vehicle.sim_time_s
    raise AssertionError("no failsafe within 60 s")


def test_the_failsafe_trips_after_the_timeout_set_live(along_world):
    default = along_world.scenario.vehicle.failsafe_s
    assert _failsafe_after_s(along_world, None) == default + along_world.scenario.control.t_cont_s
    assert _failsafe_after_s(along_world, 2 * default) > 2 * default - 1e-9


# -- the simulation's knobs, set live ---------------------------------------------------------
GPS = mavlink2.MAVLINK_MSG_ID_GPS_RAW_INT
TARGET = mavlink2.MAVLINK_MSG_ID_LANDING_TARGET


def _vehicle(world, home, sent=None) -> Vehicle:
    sink = sent if sent is not None else []
    return Vehicle(VehicleIdentity.parse("support-1"), world.scenario, world, home, 0, sink.append)


def _set(vehicle: Vehicle, name: str, value: float) -> None:
    kind = vehicle.params.table[vehicle.params.table.index_of(name)].kind
    vehicle.params.handle(mavlink2.MAVLink_param_set_message(2, 1, name.encode(), value, kind))
    assert vehicle.params.table.value(name) == value, f"{name} refused"


def _fixes(vehicle: Vehicle, count: int) -> np.ndarray:
    """ENU of ``count`` GPS_RAW_INT, one a step."""
    points = []
    for _ in range(count):
        vehicle.step()
        message = vehicle.build_stream(GPS)
        points.append(vehicle.frame.from_degE7(message.lat, message.lon, message.alt / 1000))
    return np.array(points)


ZONE_HOME = np.array([-5.0, 6.5, 8.5])  # inside Along's zone (offset +1 m east)
OPEN_HOME = np.array([0.0, -10.0, 7.0])


def test_the_defaults_give_the_world_s_fix_draw_for_draw(along_world):
    rng = np.random.default_rng(np.random.SeedSequence([0, 1]).spawn(4)[0])
    vehicle = _vehicle(along_world, ZONE_HOME)
    offset = along_world.zone_offset(ZONE_HOME[None])[0]
    for _ in range(5):
        vehicle.step()
        message = vehicle.build_stream(GPS)
        fix = along_world.gnss.sample_fix(ZONE_HOME, rng, offset)
        expected = vehicle.frame.to_degE7(fix.position_m)
        assert (message.lat, message.lon) == expected[:2]


def test_glitch_uere_and_multipath_scale_move_the_fix_as_they_say(along_world):
    healthy = _fixes(_vehicle(along_world, ZONE_HOME), 40)
    glitched = _vehicle(along_world, ZONE_HOME)
    _set(glitched, "SIM_GPS1_GLTCH_X", 2e-5)  # degrees of latitude: 2.2 m north
    _set(glitched, "SIM_GPS1_GLTCH_Z", -3.0)
    shift = (_fixes(glitched, 40) - healthy).mean(axis=0)
    np.testing.assert_allclose(shift, [0.0, 2e-5 * 111_320, -3.0], atol=0.05)
    no_bias = _vehicle(along_world, ZONE_HOME)
    _set(no_bias, "SIM_MP_SCALE", 0.0)
    np.testing.assert_allclose((_fixes(no_bias, 40) - healthy).mean(axis=0), [-1, 0, 0], atol=0.01)
    quiet = _vehicle(along_world, ZONE_HOME)
    _set(quiet, "SIM_GPS_UERE", 0.0)
    np.testing.assert_allclose(_fixes(quiet, 5), np.tile(ZONE_HOME + [1, 0, 0], (5, 1)), atol=0.02)
    noisy = _vehicle(along_world, ZONE_HOME)
    _set(noisy, "SIM_GPS_UERE", 4 * along_world.scenario.gnss.sigma_uere_m)
    spread = np.std(_fixes(noisy, 400), axis=0) / np.std(
        _fixes(_vehicle(along_world, ZONE_HOME), 400), axis=0
    )
    np.testing.assert_allclose(spread, 4.0, rtol=0.2)


def test_lag_sends_an_older_fix_stamped_now_and_the_rate_is_the_receiver_s(along_world):
    lagging, healthy = _vehicle(along_world, OPEN_HOME), _vehicle(along_world, OPEN_HOME)
    _set(lagging, "SIM_GPS1_LAG_MS", 1000)
    sent, fixes = [], []
    for _ in range(6):
        for vehicle, out in ((lagging, sent), (healthy, fixes)):
            vehicle.step()
            out.append(vehicle.build_stream(GPS))
    assert [m.time_usec for m in sent] == [m.time_usec for m in fixes]  # stamped now
    lagged = round(1.0 / along_world.scenario.control.t_cont_s)  # samples in a second
    assert [(m.lat, m.lon) for m in sent[lagged:]] == [(m.lat, m.lon) for m in fixes[:-lagged]]
    slow = _vehicle(along_world, OPEN_HOME)
    _set(slow, "SIM_GPS1_HZ", 1)
    assert slow.schedule.intervals_s[GPS] == 1.0


def _observe(vehicle: Vehicle, work: np.ndarray):
    return vehicle.camera.observe(vehicle.kinematics.truth, work)


def test_camera_range_and_noise_and_tracking_noise_and_speed(along_world):
    work = OPEN_HOME + [4.0, 0.0, 0.0]
    near = _vehicle(along_world, OPEN_HOME)
    assert _observe(near, work).valid
    _set(near, "SIM_CAM_RANGE", 3.0)
    assert not _observe(near, work).valid
    base = _vehicle(along_world, OPEN_HOME)
    louder = _vehicle(along_world, OPEN_HOME)
    _set(louder, "SIM_CAM_NOISE", 3.0)
    errors = [
        np.std([_observe(v, work).relative_m - [4, 0, 0] for _ in range(300)], axis=0)
        for v in (base, louder)
    ]
    np.testing.assert_allclose(errors[1] / errors[0], 3.0, rtol=0.2)
    mover = _vehicle(along_world, OPEN_HOME)
    _set(mover, "WPNAV_SPEED", 20.0)  # cm/s
    _set(mover, "SIM_TRACK_NOISE", 0.0)
    mover.change_mode(modes.GUIDED)
    mover.arm(True)
    mover.kinematics.target = OPEN_HOME + [10.0, 0.0, 0.0]
    mover.step()
    assert mover.kinematics.truth[0] - OPEN_HOME[0] == pytest.approx(0.2 * mover.clock.step_s)


def test_link_loss_set_live_drops_that_share_of_what_the_vehicle_sends(along_world):
    receiver = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    receiver.bind(("127.0.0.1", 0))
    receiver.settimeout(0.2)
    endpoint = UdpEndpoint(MavlinkCodec(2, 1), link_seed=5)
    vehicle = _vehicle(along_world, OPEN_HOME)
    vehicle.on_link_loss = endpoint.set_loss  # as the vehicle process wires it
    try:
        counts = []
        for loss in (0.0, 0.5, 0.0):
            _set(vehicle, "SIM_LINK_LOSS", loss)
            for _ in range(200):
                endpoint.send(vehicle.heartbeat(), [receiver.getsockname()])
            got = 0
            with contextlib.suppress(TimeoutError):
                while True:
                    receiver.recv(512)
                    got += 1
            counts.append(got)
    finally:
        endpoint.close()
        receiver.close()
    assert counts[0] == counts[2] == 200, counts
    assert 60 < counts[1] < 140, counts  # half of 200, within 5.6 sigma


def test_the_scenario_s_failure_names_are_the_vehicle_s():
    """A fault the scenario accepts is one the vehicle can inject, and the other way round."""
    from mission.config.fault_settings import FAILURE_TYPES
    from vehicle_sim.sensors import failures

    for unit, kinds in FAILURE_TYPES.items():
        for kind in kinds:
            code_unit, code_kind = failures.parse_failure(f"{unit} {kind}")
            assert code_kind in failures.SUPPORTED[code_unit]
    offered = {
        (failures.UNIT_NAMES[unit], failures.KIND_NAMES[kind])
        for unit, kinds in failures.SUPPORTED.items()
        for kind in kinds
        if kind != failures.OK
    }
    assert offered == {(u, k) for u, kinds in FAILURE_TYPES.items() for k in kinds}


def test_a_wind_set_live_pushes_a_multicopter_and_not_a_kinematic_point(along_world):
    from dataclasses import replace

    from mission.world.model import World

    flying = World(
        replace(
            along_world.scenario,
            vehicle=replace(along_world.scenario.vehicle, dynamics="multicopter"),
        )
    )
    home = np.array([0.0, 12.0, 6.0])  # in the open

    def drift(world, wind_m_s: float | None) -> float:
        vehicle = _vehicle(world, home)
        vehicle.change_mode(modes.GUIDED)
        vehicle.arm(True)
        vehicle.kinematics.hold()
        if wind_m_s is not None:
            _set(vehicle, "SIM_WIND_SPD", wind_m_s)
            _set(vehicle, "SIM_WIND_DIR", 90.0)  # from the east: it blows west
        east = []
        for _ in range(6):  # 3 s: before the failsafe (2 s) holds it, and after
            vehicle.step()
            east.append(vehicle.kinematics.truth[0] - home[0])
        return min(east)

    assert drift(flying, None) == pytest.approx(0.0, abs=1e-6)  # still air: it stays
    assert drift(flying, 6.0) < -0.05  # blown west before the autopilot catches it
    assert drift(along_world, 6.0) == 0.0  # a kinematic point feels no wind


def test_a_px4_speed_limit_set_live_slows_a_multicopter(along_world):
    from dataclasses import replace

    from mission.world.model import World

    flying = World(
        replace(
            along_world.scenario,
            vehicle=replace(along_world.scenario.vehicle, dynamics="multicopter", radius_m=None),
        )
    )
    home = np.array([0.0, 12.0, 6.0])

    def speed_after_1_5_s(limit_m_s: float | None) -> float:
        vehicle = _vehicle(flying, home)
        vehicle.change_mode(modes.GUIDED)
        vehicle.arm(True)
        if limit_m_s is not None:
            _set(vehicle, "MPC_XY_VEL_MAX", limit_m_s)
        vehicle.kinematics.target = home + [10.0, 0.0, 0.0]
        for _ in range(3):
            vehicle.step()
        return float(np.linalg.norm(vehicle.kinematics.velocity[:2]))

    assert speed_after_1_5_s(None) > 0.8  # toward the guidance's limit
    assert 0.4 < speed_after_1_5_s(0.5) <= 0.5  # most of the limit, and no more
    refused = _vehicle(flying, home)
    kind = mavlink2.MAV_PARAM_TYPE_REAL32
    refused.params.handle(mavlink2.MAVLink_param_set_message(2, 1, b"MPC_TILTMAX_AIR", 95.0, kind))
    assert refused.params.table.value("MPC_TILTMAX_AIR") == 45.0  # out of range: refused
    assert refused.kinematics.settings.tilt_max_deg == 45.0  # and the loops untouched


def test_a_gain_the_loops_could_not_fly_is_refused_live(along_world):
    from dataclasses import replace

    from mission.world.model import World

    scenario = along_world.scenario
    flying = World(replace(scenario, vehicle=replace(scenario.vehicle, dynamics="multicopter")))
    vehicle = _vehicle(flying, np.array([0.0, 12.0, 6.0]))
    kind = mavlink2.MAV_PARAM_TYPE_REAL32
    # in MPC_XY_P's range, but above the velocity loop's 1.8 / 1.5: the loops would couple
    vehicle.params.handle(mavlink2.MAVLink_param_set_message(2, 1, b"MPC_XY_P", 1.5, kind))
    assert vehicle.params.table.value("MPC_XY_P") == 0.95
    assert vehicle.kinematics.settings.position_gain_per_s == 0.95
    _set(vehicle, "MPC_XY_P", 1.1)  # within: taken
    assert vehicle.kinematics.settings.position_gain_per_s == 1.1
