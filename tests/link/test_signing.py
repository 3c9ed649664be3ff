"""MAVLink 2 signing: a signed vehicle obeys only correctly signed commands, setpoints and
mission uploads, and counts what it refused; key files are checked."""

from __future__ import annotations

import re
import time

import numpy as np
import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.config.errors import InputError
from mission.link.signing import read_signing_key
from mission.world.frames import GeodeticFrame
from tests.mav_client import MavClient, last, truth_of
from tests.processes import vehicle_process

KEY = bytes(range(32))
WRONG = bytes(range(1, 33))
HOME = np.array([0.0, -10.0, 7.0])


@pytest.fixture
def key_file(tmp_path):
    path = tmp_path / "link.key"
    path.write_text(KEY.hex() + "\n")
    return path


def _mission_count(client: MavClient, timeout_s: float) -> object:
    """Start a mission upload; the vehicle's first MISSION_REQUEST_INT, if any."""
    client.send(mavlink2.MAVLink_mission_count_message(2, 1, 2, 0))
    return client.wait_for("MISSION_REQUEST_INT", timeout_s)


@pytest.mark.slow
@pytest.mark.parametrize(
    ("client_key", "obeyed"),
    [(KEY, True), (None, False), (WRONG, False)],
    ids=["signed", "unsigned", "wrong-key"],
)
def test_a_signed_vehicle_obeys_only_signed_traffic(key_file, along, client_key, obeyed):
    frame = GeodeticFrame(along.world.anchor)
    with vehicle_process("support-1", "--signing-key", str(key_file)) as vehicle:
        client = MavClient(vehicle.address, signing_key=client_key)
        # a signed peer drives the clock, as a stream of its own (system 254): two senders on
        # one signed stream (same system, component and link) would have their timestamps
        # interleave, and the vehicle would refuse the older ones as replays
        clock = MavClient(vehicle.address, system_id=254, signing_key=KEY)
        # an answer comes within milliseconds; a refused request is given a second to show
        # that none comes (the obeyed ones return as soon as theirs does)
        wait_s = 3.0 if obeyed else 1.0
        upload = _mission_count(client, wait_s)
        mode = client.command(mavlink2.MAV_CMD_DO_SET_MODE, 1, 4, system_id=2, timeout_s=wait_s)
        arm = client.command(
            mavlink2.MAV_CMD_COMPONENT_ARM_DISARM, 1, system_id=2, timeout_s=wait_s
        )
        client.setpoint(2, HOME + np.array([3.0, 0.0, 0.0]))
        client.send(mavlink2.MAVLink_system_time_message(0, 0))  # a clock tick (a no-op)
        messages = clock.step_to(500)
        client.send(
            mavlink2.MAVLink_param_set_message(
                2, 1, b"FS_GCS_TIMEOUT", 7.0, mavlink2.MAV_PARAM_TYPE_REAL32
            )
        )
        time.sleep(0.2)
        clock.send(mavlink2.MAVLink_param_request_read_message(2, 1, b"FS_GCS_TIMEOUT", -1))
        timeout = clock.wait_for("PARAM_VALUE", where=lambda m: m.param_id == "FS_GCS_TIMEOUT")
        client.close()
        clock.close()
        log = vehicle.stop()
    assert (mode, arm) == ((mavlink2.MAV_RESULT_ACCEPTED,) * 2 if obeyed else (None, None))
    moved = np.linalg.norm(truth_of(last(messages, "SIM_STATE"), frame) - HOME)
    assert moved == pytest.approx(0.5 if obeyed else 0.0, abs=0.02)
    assert (upload is not None) == obeyed
    assert timeout is not None and timeout.param_value == (7.0 if obeyed else 2.0)  # else: not set
    refused = [line for line in log.splitlines() if "signature" in line]
    if obeyed:
        assert not refused, log
    else:  # mode, arm, setpoint, clock tick, mission count: five packets at least
        count = int(re.search(r"signature (\d+)", log).group(1))
        assert count >= 5, log


@pytest.mark.slow
def test_signed_telemetry_carries_a_signature(key_file):
    with vehicle_process("support-1", "--signing-key", str(key_file)) as vehicle:
        client = MavClient(vehicle.address, signing_key=KEY)
        messages = client.step_to(500)
        client.close()
    assert messages and all(m.get_signed() for m in messages)


@pytest.mark.slow
def test_a_repeated_tick_gets_the_step_again_signed_afresh(key_file):
    """A lost step is asked for again with the same tick; identical bytes would be replays,
    which signing refuses, so the vehicle signs the step's telemetry again."""
    with vehicle_process("support-1", "--signing-key", str(key_file)) as vehicle:
        client = MavClient(vehicle.address, signing_key=KEY)
        first = client.step_to(500)
        again = client.step_to(500)  # asserts that the step's SYSTEM_TIME came (and passed)
        client.close()
        log = vehicle.stop()
    assert [m.get_type() for m in again] == [m.get_type() for m in first]
    assert all(m.get_signed() for m in again)
    assert last(again, "SIM_STATE").lat_int == last(first, "SIM_STATE").lat_int  # same step
    assert "steps resent 1" in log


@pytest.mark.parametrize(
    ("content", "problem"),
    [
        (b"", "found 0 bytes"),
        (b"\x01" * 31, "found 31 bytes"),
        (b"z" * 64, "not hexadecimal"),
        (b"ab" * 40, "found 80 bytes"),
    ],
)
def test_bad_key_files_are_named_with_the_problem(tmp_path, content, problem):
    path = tmp_path / "bad.key"
    path.write_bytes(content)
    with pytest.raises(InputError, match=problem):
        read_signing_key(path)
    assert read_signing_key(_write(tmp_path / "raw.key", KEY)) == KEY


def _write(path, data: bytes):
    path.write_bytes(data)
    return path
