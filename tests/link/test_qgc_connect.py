"""QGroundControl's connect sequence replayed step by step against a vehicle process, as its
InitialConnectStateMachine and ParameterManager run it: AUTOPILOT_VERSION by REQUEST_MESSAGE,
component information and standard modes (refused: QGroundControl moves on), the full
parameter download (PARAM_REQUEST_LIST, 5 s for a first answer, then reads by index in batches
of 10 for whatever did not come), the mission download, geofence and rally points skipped for
want of their capability bits, and then "connected"."""

from __future__ import annotations

import time

import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from tests.mav_client import MavClient
from tests.mission_download import DownloadingClient
from tests.processes import vehicle_process

pytestmark = pytest.mark.slow  # a vehicle process
SYSID = 2  # support-1
REQUEST = mavlink2.MAV_CMD_REQUEST_MESSAGE
COMPONENT_METADATA, COMPONENT_INFORMATION, AVAILABLE_MODES = 397, 395, 435
FIRST_ANSWER_S = 5.0  # ParameterManager's wait for the list's first PARAM_VALUE
BATCH = 10  # its reads by index of the missing ones, at a time
LOST = {2, 5, 8}  # indexes whose PARAM_VALUE the test drops from the list's answer
GCS_HEARTBEAT = mavlink2.MAVLink_heartbeat_message(
    mavlink2.MAV_TYPE_GCS, mavlink2.MAV_AUTOPILOT_INVALID, 0, 0, mavlink2.MAV_STATE_ACTIVE, 3
)


def _download_parameters(client: MavClient) -> dict[int, object]:
    """The list, then the missing ones read by index, BATCH at a time, until all have come
    (at most 5 rounds)."""
    client.send(mavlink2.MAVLink_param_request_list_message(SYSID, 1))
    first = client.wait_for("PARAM_VALUE", timeout_s=FIRST_ANSWER_S)
    assert first is not None, "no answer to PARAM_REQUEST_LIST within 5 s"
    values = {first.param_index: first}
    count = first.param_count
    listed = _parameter_values(client.collect(0.5))
    # three of the list's datagrams lost on the way: QGroundControl reads them by index
    values.update((m.param_index, m) for m in listed if m.param_index not in LOST)
    for _ in range(5):
        values.update((m.param_index, m) for m in _parameter_values(client.collect(0.5)))
        missing = sorted(set(range(count)) - set(values))[:BATCH]
        if not missing:
            return values
        for index in missing:
            client.send(mavlink2.MAVLink_param_request_read_message(SYSID, 1, b"", index))
    raise AssertionError(f"{count - len(values)} parameters never came")


def _seen_or_next(client: MavClient, kind: str):
    """The last ``kind`` message already received, else the next one."""
    seen = [m for m in client.seen if m.get_type() == kind]
    return seen[-1] if seen else client.wait_for(kind, timeout_s=2.0)


def _parameter_values(messages: list) -> list:
    return [m for m in messages if m.get_type() == "PARAM_VALUE"]


def test_qgroundcontrol_s_connect_sequence_completes(tmp_path):
    with vehicle_process("support-1", "--speedup", "1") as vehicle:
        client = MavClient(vehicle.address)
        try:
            started = time.monotonic()
            client.send(GCS_HEARTBEAT)  # QGroundControl announces itself once a second
            assert client.wait_for("HEARTBEAT", timeout_s=5.0) is not None
            ack = client.command(
                REQUEST, mavlink2.MAVLINK_MSG_ID_AUTOPILOT_VERSION, system_id=SYSID
            )
            assert ack == mavlink2.MAV_RESULT_ACCEPTED
            version = _seen_or_next(client, "AUTOPILOT_VERSION")  # it may come before the ack
            assert version is not None
            capabilities = version.capabilities
            assert capabilities & mavlink2.MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_C_CAST
            assert capabilities & mavlink2.MAV_PROTOCOL_CAPABILITY_MISSION_INT
            for message_id in (COMPONENT_METADATA, COMPONENT_INFORMATION, AVAILABLE_MODES):
                refused = client.command(REQUEST, message_id, system_id=SYSID)
                assert refused == mavlink2.MAV_RESULT_UNSUPPORTED  # QGroundControl moves on
            parameters = _download_parameters(client)
            assert {p.param_id for p in parameters.values()} >= {"FS_GCS_TIMEOUT", "SIM_SPEEDUP"}
            mission = DownloadingClient(client.queue, vehicle.address, SYSID, timeout_s=1.0)
            assert mission.download() == []  # nothing uploaded yet: an empty mission
            for bit in ("MISSION_FENCE", "MISSION_RALLY"):  # so both downloads are skipped
                assert not capabilities & getattr(mavlink2, f"MAV_PROTOCOL_CAPABILITY_{bit}")
            assert time.monotonic() - started < 10.0  # connected
        finally:
            client.close()
