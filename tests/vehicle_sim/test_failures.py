"""MAV_CMD_INJECT_FAILURE against a real vehicle process, with pymavlink as the peer: refused
until SIM_FAIL_ENABLE allows it, unsupported units and types said so, and each supported GNSS
failure doing to GPS_RAW_INT what it says."""

from __future__ import annotations

import re

import numpy as np
import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from tests.mav_client import MavClient
from tests.processes import vehicle_process

pytestmark = pytest.mark.slow  # a vehicle process
SYSID = 2  # support-1
GPS, VIO = mavlink2.FAILURE_UNIT_SENSOR_GPS, mavlink2.FAILURE_UNIT_SENSOR_VIO
INJECT = mavlink2.MAV_CMD_INJECT_FAILURE


@pytest.fixture
def client():
    with vehicle_process("support-1", "--speedup", "10") as vehicle:  # fixes come quicker
        mav = MavClient(vehicle.address)
        yield mav
        mav.close()


def _enable(client: MavClient) -> None:
    set_ = mavlink2.MAVLink_param_set_message(
        SYSID, 1, b"SIM_FAIL_ENABLE", 1, mavlink2.MAV_PARAM_TYPE_INT32
    )
    client.send(set_)
    echo = client.wait_for("PARAM_VALUE", where=lambda m: m.param_id == "SIM_FAIL_ENABLE")
    assert echo is not None and echo.param_value == 1


def _fixes(client: MavClient, seconds: float) -> np.ndarray:
    """(lat, lon) of the GPS_RAW_INT that come within ``seconds``."""
    got = [m for m in client.collect(seconds) if m.get_type() == "GPS_RAW_INT"]
    return np.array([(m.lat, m.lon) for m in got], dtype=float).reshape(-1, 2)


def test_failures_are_refused_until_enabled_and_unsupported_ones_say_so(client):
    assert client.command(INJECT, GPS, mavlink2.FAILURE_TYPE_OFF, system_id=SYSID) == (
        mavlink2.MAV_RESULT_DENIED
    )
    _enable(client)
    motor = mavlink2.FAILURE_UNIT_SYSTEM_MOTOR
    assert client.command(INJECT, motor, mavlink2.FAILURE_TYPE_OFF, system_id=SYSID) == (
        mavlink2.MAV_RESULT_UNSUPPORTED
    )
    slow = mavlink2.FAILURE_TYPE_SLOW
    assert client.command(INJECT, VIO, slow, system_id=SYSID) == mavlink2.MAV_RESULT_UNSUPPORTED


def test_gnss_off_stuck_wrong_and_back(client):
    _enable(client)
    healthy = _fixes(client, 1.0)
    assert len(healthy) >= 3 and len(np.unique(healthy, axis=0)) > 1  # noise: fixes differ
    ok = mavlink2.MAV_RESULT_ACCEPTED
    assert client.command(INJECT, GPS, mavlink2.FAILURE_TYPE_OFF, system_id=SYSID) == ok
    said = [m.text for m in client.seen if m.get_type() == "STATUSTEXT"]
    client.collect(0.3)
    assert len(_fixes(client, 1.0)) == 0
    said += [m.text for m in client.seen if m.get_type() == "STATUSTEXT"]
    assert any(re.fullmatch(r"Failure gps off t=\d+\.\d\d", t) for t in said)
    assert client.command(INJECT, GPS, mavlink2.FAILURE_TYPE_STUCK, system_id=SYSID) == ok
    client.collect(0.3)
    stuck = _fixes(client, 1.0)
    assert len(stuck) >= 3 and len(np.unique(stuck, axis=0)) == 1
    assert client.command(INJECT, GPS, mavlink2.FAILURE_TYPE_WRONG, system_id=SYSID) == ok
    client.collect(0.3)
    wrong = _fixes(client, 2.0)
    north = (wrong[:, 0].mean() - healthy[:, 0].mean()) * 1e-7 * 111_320.0
    assert north == pytest.approx(10.0, abs=1.5)  # 10 m north, within the fixes' noise
    assert client.command(INJECT, GPS, mavlink2.FAILURE_TYPE_OK, system_id=SYSID) == ok
    client.collect(0.3)
    back = _fixes(client, 1.0)
    assert len(back) >= 3 and abs(back[:, 0].mean() - healthy[:, 0].mean()) * 0.0111 < 1.5


def test_sim_gps1_enable_turns_the_receiver_off_and_on_as_ardupilot_s_does(client):
    """No failure-injection gate: a parameter set, said in a STATUSTEXT (so the tlog has it)."""
    for value, publishing in ((0, False), (1, True)):
        client.send(
            mavlink2.MAVLink_param_set_message(
                SYSID, 1, b"SIM_GPS1_ENABLE", value, mavlink2.MAV_PARAM_TYPE_INT32
            )
        )
        echo = client.wait_for("PARAM_VALUE", where=lambda m: m.param_id == "SIM_GPS1_ENABLE")
        assert echo is not None and echo.param_value == value
        client.collect(0.3)
        assert (len(_fixes(client, 1.0)) > 0) == publishing
    said = [m.text for m in client.seen if m.get_type() == "STATUSTEXT"]
    for value in (0, 1):
        assert any(re.fullmatch(rf"Set SIM_GPS1_ENABLE={value} t=\d+\.\d\d", t) for t in said)
