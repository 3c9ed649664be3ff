"""A vehicle process in lockstep, driven through real MAVLink: motion, sensors, failsafe."""

from __future__ import annotations

import os
import sys

import numpy as np
import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.world.frames import GeodeticFrame, ned_to_enu
from tests.mav_client import MavClient, last, truth_of
from tests.processes import vehicle_process

pytestmark = pytest.mark.slow  # every test here starts processes

STEP_MS = 500
QUANTUM_M = 0.012  # 1e-7 degree of latitude is 1.1 cm: SIM_STATE's resolution


@pytest.fixture(scope="module")
def frame(along) -> GeodeticFrame:
    return GeodeticFrame(along.world.anchor)


def test_setpoint_moves_at_the_speed_limit_toward_the_target(frame):
    home = np.array([0.0, -10.0, 7.0])
    target = home + np.array([6.0, -8.0, 0.0])  # 10 m away
    with vehicle_process("support-1", home=tuple(home)) as vehicle:
        client = MavClient(vehicle.address)
        client.arm_guided(2)
        positions = []
        for k in range(1, 25):
            client.setpoint(2, target)  # a ground station streams setpoints every cycle
            positions.append(truth_of(last(client.step_to(STEP_MS * k), "SIM_STATE"), frame))
        client.close()
    moves = np.linalg.norm(np.diff([home, *positions], axis=0), axis=1)
    np.testing.assert_allclose(moves[:19], 0.5, atol=QUANTUM_M)  # 1.0 m/s x 0.5 s
    direction = (positions[5] - home) / np.linalg.norm(positions[5] - home)
    np.testing.assert_allclose(direction, (target - home) / 10.0, atol=0.01)
    np.testing.assert_allclose(positions[-1], target, atol=QUANTUM_M)


def test_work_uav_is_slower_and_a_wrong_estimate_moves_the_truth_wrongly(frame):
    home = np.array([0.0, 0.0, 6.0])
    error = np.array([0.4, -0.3, 0.2])
    target = home + np.array([1.0, 0.0, 0.0])
    with vehicle_process("work", home=tuple(home)) as vehicle:
        client = MavClient(vehicle.address)
        client.arm_guided(1)
        client.estimate(home + error)  # the ground station believes it is elsewhere
        client.setpoint(1, target)
        first = truth_of(last(client.step_to(STEP_MS), "SIM_STATE"), frame)
        for k in range(2, 14):
            client.setpoint(1, target)
            messages = client.step_to(STEP_MS * k)
        client.close()
    assert np.linalg.norm(first - home) == pytest.approx(0.15, abs=QUANTUM_M)  # 0.3 m/s
    truth = truth_of(last(messages, "SIM_STATE"), frame)
    np.testing.assert_allclose(truth, target - error, atol=QUANTUM_M)
    local = last(messages, "LOCAL_POSITION_NED")
    believed = ned_to_enu(np.array([local.x, local.y, local.z]))
    np.testing.assert_allclose(believed, target, atol=1e-4)


def test_a_stamped_setpoint_sent_again_is_ignored_and_a_new_one_is_taken(frame):
    """A batch sent again after the vehicle stepped on the first carries its setpoint again:
    ignored (counted), where a new setpoint with the same stamp, or an unstamped one, is
    taken."""
    home = np.array([0.0, 0.0, 6.0])
    first, second = home + [1.0, 0.0, 0.0], home + [0.0, 1.0, 0.0]
    with vehicle_process("work", home=tuple(home)) as vehicle:
        client = MavClient(vehicle.address)
        client.arm_guided(1)
        client.estimate(home, usec=1)
        client.setpoint(1, first, time_boot_ms=STEP_MS)
        client.step_to(STEP_MS)
        client.setpoint(1, first, time_boot_ms=STEP_MS)  # the same datagram again: ignored
        client.setpoint(1, second, time_boot_ms=STEP_MS)  # another target, same stamp: taken
        client.setpoint(1, second)  # unstamped: taken however often it comes
        for k in range(2, 12):
            client.setpoint(1, second, time_boot_ms=STEP_MS * k)  # streamed, as a station does
            messages = client.step_to(STEP_MS * k)
        client.close()
        said = vehicle.stop()
    np.testing.assert_allclose(_believed(messages), second, atol=1e-4)
    assert "'setpoint: repeated': 1" in said


def test_an_estimate_stamped_no_later_than_the_last_taken_is_ignored(frame):
    """A datagram delivered twice (or overtaken) would set the belief back after the vehicle
    moved on: the vehicle takes an estimate only if its sender stamped it later than the last
    one it took (unstamped ones always); one stamped more than 2 s back is a sender that
    started again, taken and said."""
    home = np.array([0.0, 0.0, 6.0])
    first_estimate, repeated, older, newer_estimate = (
        home + offset for offset in ([0.5, 0, 0], [0, 0.7, 0], [0, 0.9, 0], [0, 0, 0.4])
    )
    restarted_estimate = home + [0.0, -0.6, 0.0]
    with vehicle_process("work", home=tuple(home)) as vehicle:
        client = MavClient(vehicle.address)
        client.arm_guided(1)
        client.estimate(first_estimate, usec=20_000_000)
        client.setpoint(1, first_estimate)  # it holds where it believes it is
        first = _believed(client.step_to(STEP_MS))
        client.estimate(repeated, usec=20_000_000)  # the same stamp again
        client.estimate(older, usec=19_000_000)  # an older one
        client.setpoint(1, first_estimate)
        held = _believed(client.step_to(2 * STEP_MS))
        client.estimate(newer_estimate, usec=21_000_000)
        client.setpoint(1, newer_estimate)
        newer = _believed(client.step_to(3 * STEP_MS))
        client.estimate(home, usec=0)  # unstamped
        client.setpoint(1, home)
        unstamped = _believed(client.step_to(4 * STEP_MS))
        client.estimate(restarted_estimate, usec=500_000)  # 20.5 s back: a new sender session
        client.setpoint(1, restarted_estimate)
        messages = client.step_to(5 * STEP_MS)
        client.close()
    np.testing.assert_allclose(first, first_estimate, atol=1e-4)
    np.testing.assert_allclose(held, first, atol=1e-4)
    np.testing.assert_allclose(newer, newer_estimate, atol=1e-4)
    np.testing.assert_allclose(unstamped, home, atol=1e-4)
    np.testing.assert_allclose(_believed(messages), restarted_estimate, atol=1e-4)
    said = [m.text for m in messages if m.get_type() == "STATUSTEXT"]
    assert "Estimates restarted: stamps 20.5 s back" in said, said


def _believed(messages) -> np.ndarray:
    local = last(messages, "LOCAL_POSITION_NED")
    return ned_to_enu(np.array([local.x, local.y, local.z]))


def _fixes(messages, frame) -> np.ndarray:
    return np.array(
        [
            frame.from_degE7(m.lat, m.lon, m.alt / 1000.0)
            for m in messages
            if m.get_type() == "GPS_RAW_INT" and m.fix_type >= 3
        ]
    )


@pytest.mark.parametrize("inside", [True, False], ids=["in-zone", "open"])
def test_gps_statistics_follow_the_model_with_bias_only_in_the_zone(along_world, frame, inside):
    zone = along_world.scenario.world.zones[0]
    point = (
        (np.array(zone.min_m) + np.array(zone.max_m)) / 2 if inside else np.array([0.0, -15.0, 8.0])
    )
    assert along_world.in_zone(point[None])[0] == inside
    has_fix, sigma = along_world.gnss.sigma_gnss(point[None])
    assert has_fix[0]
    with vehicle_process("support-1", home=tuple(point)) as vehicle:
        client = MavClient(vehicle.address)
        messages = [m for k in range(1, 401) for m in client.step_to(STEP_MS * k)]
        client.close()
    fixes = _fixes(messages, frame)
    assert len(fixes) == 400
    bias = np.array(zone.offset_m) if inside else np.zeros(3)
    errors = fixes - point
    standard_error = np.sqrt(np.diag(sigma[0]) / len(fixes))
    np.testing.assert_array_less(np.abs(errors.mean(axis=0) - bias), 4 * standard_error + 0.006)
    np.testing.assert_allclose(errors.std(axis=0), np.sqrt(np.diag(sigma[0])), rtol=0.2)
    gps = last(messages, "GPS_RAW_INT")
    geometry = along_world.gnss.geometry(point[None])
    assert gps.h_acc == round(0.10 * geometry.hdop[0] * 1000)
    assert gps.eph == round(geometry.hdop[0] * 100)
    assert gps.satellites_visible == int(geometry.n_visible[0])


def test_landing_target_is_valid_only_with_a_clear_line_of_sight():
    work_home = (0.0, 0.0, 6.0)
    beside, above = (0.0, -9.0, 6.0), (0.0, 0.0, 12.0)
    with (
        vehicle_process("support-1", home=beside) as s1,
        vehicle_process("support-2", home=above) as s2,
        vehicle_process(
            "work",
            "--truth-out",
            f"127.0.0.1:{s1.truth_port}",
            "--truth-out",
            f"127.0.0.1:{s2.truth_port}",
            home=work_home,
        ) as work,
    ):
        client = MavClient(work.address, s1.address, s2.address)
        messages = [m for k in range(1, 6) for m in client.step_to(STEP_MS * k)]
        client.close()
    seen = last(messages, "LANDING_TARGET", system_id=2)
    hidden = last(messages, "LANDING_TARGET", system_id=3)
    assert seen.position_valid == 1 and seen.target_num == 1
    assert seen.frame == mavlink2.MAV_FRAME_LOCAL_OFFSET_NED
    relative_enu = ned_to_enu(np.array([seen.x, seen.y, seen.z]))
    np.testing.assert_allclose(relative_enu, np.array(work_home) - np.array(beside), atol=0.5)
    assert seen.distance == pytest.approx(np.linalg.norm(relative_enu), rel=1e-5)
    assert hidden.position_valid == 0
    assert not any(m.get_type() == "LANDING_TARGET" for m in messages if m.get_srcSystem() == 1)


def test_failsafe_holds_after_the_set_time_and_clears(frame):
    home = np.array([0.0, -10.0, 7.0])
    with vehicle_process("support-1", home=tuple(home)) as vehicle:
        client = MavClient(vehicle.address)
        client.arm_guided(2)
        client.setpoint(2, home + np.array([20.0, 0.0, 0.0]))
        texts = []
        positions = []
        for k in range(1, 9):  # no setpoint after t = 0: failsafe after 2 s (scenario default)
            messages = client.step_to(STEP_MS * k)
            texts += [(k, m.text) for m in messages if m.get_type() == "STATUSTEXT"]
            positions.append(truth_of(last(messages, "SIM_STATE"), frame))
        fired = [k for k, text in texts if text.startswith("Failsafe: no setpoint")]
        assert fired == [5], texts  # checked at the start of the step after 2.0 s
        assert np.linalg.norm(positions[-1] - positions[4]) < QUANTUM_M, "holds position"
        heartbeat = last(client.seen, "HEARTBEAT")
        client.setpoint(2, home + np.array([20.0, 0.0, 0.0]))
        messages = client.step_to(STEP_MS * 9)
        moved = truth_of(last(messages, "SIM_STATE"), frame)
        client.close()
    assert any(m.get_type() == "STATUSTEXT" and "Failsafe cleared" in m.text for m in client.seen)
    assert heartbeat.system_status == mavlink2.MAV_STATE_CRITICAL
    assert np.linalg.norm(moved - positions[-1]) == pytest.approx(0.5, abs=QUANTUM_M)


def test_commands_are_acknowledged(frame):
    with vehicle_process("support-2", "--speedup", "1") as vehicle:
        client = MavClient(vehicle.address)
        ok = mavlink2.MAV_RESULT_ACCEPTED
        assert (
            client.command(
                mavlink2.MAV_CMD_REQUEST_MESSAGE,
                mavlink2.MAVLINK_MSG_ID_AUTOPILOT_VERSION,
                system_id=3,
            )
            == ok
        )
        version = last(client.seen, "AUTOPILOT_VERSION")
        assert version.capabilities & mavlink2.MAV_PROTOCOL_CAPABILITY_MISSION_INT
        assert version.capabilities & mavlink2.MAV_PROTOCOL_CAPABILITY_MAVLINK2
        assert (
            client.command(
                mavlink2.MAV_CMD_SET_MESSAGE_INTERVAL,
                mavlink2.MAVLINK_MSG_ID_GPS_RAW_INT,
                -1,
                system_id=3,
            )
            == ok
        )
        client.collect(0.3)
        assert not [m for m in client.collect(1.5) if m.get_type() == "GPS_RAW_INT"]
        assert (
            client.command(mavlink2.MAV_CMD_SET_MESSAGE_INTERVAL, 9999, 1e6, system_id=3)
            == mavlink2.MAV_RESULT_UNSUPPORTED
        )
        # ids and intervals MESSAGE_INTERVAL cannot carry (uint16, int32) are refused, answered
        denied = mavlink2.MAV_RESULT_DENIED
        for command, params in (
            (mavlink2.MAV_CMD_GET_MESSAGE_INTERVAL, (70000,)),
            (mavlink2.MAV_CMD_GET_MESSAGE_INTERVAL, (-1,)),
            (mavlink2.MAV_CMD_GET_MESSAGE_INTERVAL, (1e30,)),
            (mavlink2.MAV_CMD_SET_MESSAGE_INTERVAL, (99999, 1e6)),
            (mavlink2.MAV_CMD_SET_MESSAGE_INTERVAL, (24, 1e30)),
        ):
            assert client.command(command, *params, system_id=3) == denied, (command, params)
        assert client.command(mavlink2.MAV_CMD_GET_MESSAGE_INTERVAL, 24, system_id=3) == ok
        assert (
            client.command(mavlink2.MAV_CMD_DO_SET_MODE, 1, 77, system_id=3)
            == mavlink2.MAV_RESULT_DENIED
        )
        assert (
            client.command(mavlink2.MAV_CMD_DO_SET_MODE, 1, 6 << 16, system_id=3) == ok
        )  # PX4 OFFBOARD means GUIDED here
        assert client.command(mavlink2.MAV_CMD_COMPONENT_ARM_DISARM, 1, system_id=3) == ok
        heartbeat = client.wait_for("HEARTBEAT", 3.0, where=lambda m: m.base_mode & 128)
        assert heartbeat is not None and heartbeat.custom_mode == 4
        assert heartbeat.type == mavlink2.MAV_TYPE_QUADROTOR
        assert (
            client.command(mavlink2.MAV_CMD_NAV_TAKEOFF, system_id=3)
            == mavlink2.MAV_RESULT_UNSUPPORTED
        )
        client.setpoint(3, np.zeros(3), type_mask=0)  # velocity and acceleration not ignored
        text = client.wait_for("STATUSTEXT", 3.0)
        assert "type_mask" in text.text
        client.send(mavlink2.MAVLink_timesync_message(0, 123456))
        sync = client.wait_for("TIMESYNC", 3.0)
        assert sync.ts1 == 123456 and sync.tc1 > 0
        client.close()


@pytest.mark.parametrize(
    ("target", "reason"),
    [
        ((30.0, -10.0, 7.0), "outside the workspace"),
        ((0.0, 0.0, 8.5), "inside the structure"),
        ((0.0, 0.0, 9.5), "crosses structure"),  # on the deck, reached only through it
    ],
)
def test_geofence_refuses_setpoints_and_the_vehicle_holds(frame, target, reason):
    home = np.array([0.0, -10.0, 7.0])
    with vehicle_process("support-1", home=tuple(home)) as vehicle:
        client = MavClient(vehicle.address)
        client.arm_guided(2)
        client.setpoint(2, home + np.array([0.0, -3.0, 0.0]))  # moving away from the bridge
        moving = truth_of(last(client.step_to(STEP_MS), "SIM_STATE"), frame)
        client.setpoint(2, np.array(target))
        messages = client.step_to(2 * STEP_MS)
        for k in range(3, 6):
            messages += client.step_to(STEP_MS * k)
        held = truth_of(last(messages, "SIM_STATE"), frame)
        client.setpoint(2, home + np.array([3.0, 0.0, 0.0]))  # a good setpoint is taken again
        after = truth_of(last(client.step_to(6 * STEP_MS), "SIM_STATE"), frame)
        client.close()
    texts = [m.text for m in messages if m.get_type() == "STATUSTEXT"]
    assert f"Setpoint rejected: fence: {reason}" in texts, texts
    assert np.linalg.norm(held - moving) < QUANTUM_M, "stops where it was told to leave the fence"
    assert np.linalg.norm(after - held) == pytest.approx(0.5, abs=QUANTUM_M)


def _threads(pid: int) -> int:
    return len(os.listdir(f"/proc/{pid}/task"))


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="needs /proc")
def test_a_vehicle_asks_blas_for_one_thread_unless_told(monkeypatch):
    def threads(setting: str | None) -> int:
        if setting is None:
            monkeypatch.delenv("OPENBLAS_NUM_THREADS", raising=False)
        else:
            monkeypatch.setenv("OPENBLAS_NUM_THREADS", setting)
        with vehicle_process("support-1") as vehicle:
            return _threads(vehicle.process.pid)

    unset = threads(None)
    assert unset == threads("1")  # OpenBLAS would start one worker per core
    if (os.cpu_count() or 1) >= 2:
        assert threads("2") == unset + 1
