"""Mission protocol against a real vehicle process over UDP."""

from __future__ import annotations

import numpy as np
import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.link.mission_items import MISSION, MissionItem
from mission.link.waypoints import (
    WaypointRow,
    format_waypoints,
    read_waypoints,
    waypoint_rows_from_enu,
    write_waypoints,
)
from mission.world.frames import GeodeticFrame
from tests.mav_client import MavClient
from tests.mission_download import DownloadingClient, row_from_item
from tests.processes import vehicle_process

SYSID = 2  # support-1


@pytest.fixture(scope="module")
def waypoint_file(tmp_path_factory, along):
    points = np.array(
        [[-3.0, -9.5, 7.25], [0.0, -10.0, 7.0], [4.5, -11.125, 8.5], [9.0, -9.0, 6.0]]
    )
    rows = waypoint_rows_from_enu(points, GeodeticFrame(along.world.anchor), acceptance_m=0.1)
    path = tmp_path_factory.mktemp("wp") / "support-1.waypoints"
    write_waypoints(path, rows)
    return path


@pytest.fixture(scope="module")
def scenario_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("scn") / "fast-timeouts.yaml"
    path.write_text("extends: along\nvehicle: {mission_timeout_wall_s: 0.2, mission_retries: 2}\n")
    return path


@pytest.fixture(scope="module")
def vehicle(scenario_file):
    with vehicle_process("support-1", "--speedup", "1", scenario=str(scenario_file)) as running:
        yield running


def _rows(items: list[MissionItem]) -> list[WaypointRow]:
    """Compare missions as their file rows (float32 fields back to their decimals)."""
    return [row_from_item(item) for item in items]


def _mission_client(client: MavClient) -> DownloadingClient:
    return DownloadingClient(client.queue, client.vehicle, SYSID, timeout_s=1.0, retries=3)


@pytest.mark.slow
def test_upload_download_round_trip_is_byte_identical(client, waypoint_file, tmp_path):
    items = [row.to_item() for row in read_waypoints(waypoint_file)]
    mission = _mission_client(client)
    assert mission.upload(items) == mavlink2.MAV_MISSION_ACCEPTED
    downloaded = mission.download()
    saved = tmp_path / "downloaded.waypoints"
    write_waypoints(saved, [row_from_item(item) for item in downloaded])
    assert saved.read_bytes() == waypoint_file.read_bytes()


def test_files_round_trip_through_mavwp(waypoint_file, tmp_path):
    from pymavlink import mavwp

    loader = mavwp.MAVWPLoader()
    loader.load(str(waypoint_file))
    loader.save(str(tmp_path / "mavwp.waypoints"))
    assert (tmp_path / "mavwp.waypoints").read_bytes() == waypoint_file.read_bytes()
    assert format_waypoints(read_waypoints(waypoint_file)) == waypoint_file.read_text()


def _item(seq: int, **changes) -> object:
    fields = dict(
        frame=mavlink2.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
        command=16,
        current=0,
        autocontinue=1,
        param1=0.0,
        param2=0.1,
        param3=0.0,
        param4=0.0,
        x=351500000,
        y=1369600000,
        z=7.0,
    )
    fields.update(changes)
    return MissionItem(seq, **fields).to_int_message((SYSID, 1))


def _ack(client: MavClient) -> int | None:
    ack = client.wait_for("MISSION_ACK", 3.0)
    return None if ack is None else int(ack.type)


BAD_UPLOADS = [
    ("item without count", [], [_item(0)], mavlink2.MAV_MISSION_INVALID_SEQUENCE),
    ("skipped item", [2], [_item(0), _item(2)], mavlink2.MAV_MISSION_INVALID_SEQUENCE),
    (
        "local frame",
        [2],
        [_item(0, frame=mavlink2.MAV_FRAME_LOCAL_NED)],
        mavlink2.MAV_MISSION_UNSUPPORTED_FRAME,
    ),
    ("unknown command", [2], [_item(0, command=31999)], mavlink2.MAV_MISSION_UNSUPPORTED),
    ("latitude out of range", [2], [_item(0, x=950000000)], mavlink2.MAV_MISSION_INVALID_PARAM5_X),
    ("too many items", [60_000], [], mavlink2.MAV_MISSION_NO_SPACE),
]


@pytest.mark.slow
@pytest.mark.parametrize(
    ("case", "count", "items", "result"), BAD_UPLOADS, ids=[c[0] for c in BAD_UPLOADS]
)
def test_bad_upload_gets_its_nack_and_leaves_the_mission(
    client, waypoint_file, case, count, items, result
):
    original = [row.to_item() for row in read_waypoints(waypoint_file)]
    mission = _mission_client(client)
    assert mission.upload(original) == mavlink2.MAV_MISSION_ACCEPTED
    if count:
        client.send(mavlink2.MAVLink_mission_count_message(SYSID, 1, count[0], MISSION))
        if items:
            assert client.wait_for("MISSION_REQUEST_INT", 3.0) is not None
    for message in items:
        client.send(message)
        if message is not items[-1]:
            client.wait_for("MISSION_REQUEST_INT", 3.0)
    assert _ack(client) == result
    assert _rows(mission.download()) == _rows(original)


@pytest.mark.slow
def test_fence_upload_is_unsupported_and_fence_download_is_empty(client):
    client.send(
        mavlink2.MAVLink_mission_count_message(SYSID, 1, 3, mavlink2.MAV_MISSION_TYPE_FENCE)
    )
    assert _ack(client) == mavlink2.MAV_MISSION_UNSUPPORTED
    client.send(
        mavlink2.MAVLink_mission_request_list_message(SYSID, 1, mavlink2.MAV_MISSION_TYPE_FENCE)
    )
    count = client.wait_for("MISSION_COUNT", 3.0)
    assert count is not None and count.count == 0


@pytest.mark.slow
def test_silent_uploader_is_re_requested_then_cancelled(client, waypoint_file):
    original = [row.to_item() for row in read_waypoints(waypoint_file)]
    mission = _mission_client(client)
    assert mission.upload(original) == mavlink2.MAV_MISSION_ACCEPTED
    client.send(mavlink2.MAVLink_mission_count_message(SYSID, 1, 5, MISSION))
    ack = client.wait_for("MISSION_ACK", 5.0)
    requests = [m for m in client.seen if m.get_type() == "MISSION_REQUEST_INT" and m.seq == 0]
    assert ack is not None and ack.type == mavlink2.MAV_MISSION_OPERATION_CANCELLED
    assert len(requests) == 3, "first request + mission_retries (2) re-requests"
    assert _rows(mission.download()) == _rows(original)


@pytest.mark.slow
def test_clear_set_current_and_item_reached(client, waypoint_file):
    items = [row.to_item() for row in read_waypoints(waypoint_file)]
    mission = _mission_client(client)
    assert mission.upload(items) == mavlink2.MAV_MISSION_ACCEPTED
    client.send(mavlink2.MAVLink_mission_set_current_message(SYSID, 1, 3))
    reached = [client.wait_for("MISSION_ITEM_REACHED", 3.0) for _ in range(3)]
    assert [m.seq for m in reached] == [0, 1, 2]
    current = client.wait_for("MISSION_CURRENT", 3.0, where=lambda m: m.seq == 3)
    assert current is not None and current.total == len(items)
    client.send(mavlink2.MAVLink_mission_clear_all_message(SYSID, 1, MISSION))
    assert _ack(client) == mavlink2.MAV_MISSION_ACCEPTED
    assert mission.download() == []


@pytest.mark.slow
def test_messages_for_another_system_are_ignored(client, waypoint_file):
    items = [row.to_item() for row in read_waypoints(waypoint_file)]
    mission = _mission_client(client)
    assert mission.upload(items) == mavlink2.MAV_MISSION_ACCEPTED
    client.send(mavlink2.MAVLink_mission_clear_all_message(SYSID + 5, 1, MISSION))
    assert _ack(client) is None
    assert _rows(mission.download()) == _rows(items)


@pytest.mark.slow
def test_the_last_item_sent_again_gets_the_final_ack_again(client, waypoint_file):
    """When the vehicle's final MISSION_ACK is lost, the ground station repeats the last item:
    the vehicle must acknowledge again, not report a sequence error."""
    items = [row.to_item() for row in read_waypoints(waypoint_file)]
    mission = _mission_client(client)
    assert mission.upload(items) == mavlink2.MAV_MISSION_ACCEPTED
    client.send(items[-1].to_int_message((SYSID, 1)))
    assert _ack(client) == mavlink2.MAV_MISSION_ACCEPTED
    client.send(items[-2].to_int_message((SYSID, 1)))  # any other item is still an error
    assert _ack(client) == mavlink2.MAV_MISSION_INVALID_SEQUENCE
