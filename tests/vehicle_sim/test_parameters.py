"""The parameter protocol against a real vehicle process, with pymavlink as the peer: the whole
list once, reads by index and by id, a set echoed, refusals echoed unchanged and said why."""

from __future__ import annotations

import math
import time

import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.link.statustext import StatusChunks
from tests.mav_client import MavClient
from tests.processes import vehicle_process

pytestmark = pytest.mark.slow  # a vehicle process
SYSID = 2  # support-1


@pytest.fixture(scope="module")
def vehicle():
    with vehicle_process("support-1", "--speedup", "1") as running:
        yield running


def _download(client: MavClient) -> dict[int, object]:
    client.send(mavlink2.MAVLink_param_request_list_message(SYSID, 1))
    values: dict[int, object] = {}
    deadline = time.monotonic() + 5.0
    while time.monotonic() < deadline:
        got = client.wait_for("PARAM_VALUE", timeout_s=deadline - time.monotonic())
        assert got is not None, f"{len(values)} parameters came"
        values.setdefault(got.param_index, got)
        if len(values) == got.param_count:
            return values
    raise AssertionError("the list did not complete")


def _read(client: MavClient, name: str = "", index: int = -1):
    request = mavlink2.MAVLink_param_request_read_message(SYSID, 1, name.encode(), index)
    client.send(request)
    return client.wait_for("PARAM_VALUE", timeout_s=2.0)


def _set(client: MavClient, name: str, value: float, kind=mavlink2.MAV_PARAM_TYPE_REAL32):
    client.send(mavlink2.MAVLink_param_set_message(SYSID, 1, name.encode(), value, kind))
    return client.wait_for("PARAM_VALUE", timeout_s=2.0, where=lambda m: m.param_id == name)


def test_the_whole_list_comes_once_in_under_half_a_second(client):
    started = time.monotonic()
    values = _download(client)
    assert time.monotonic() - started < 0.5
    count = next(iter(values.values())).param_count
    assert sorted(values) == list(range(count))
    names = [v.param_id for v in values.values()]
    assert len(set(names)) == count and all(0 < len(n) <= 16 for n in names)
    assert {"FS_GCS_TIMEOUT", "SIM_SPEEDUP", "WPNAV_SPEED"} <= set(names)

    def table(download):
        return [(i, v.param_id, v.param_type) for i, v in sorted(download.items())]

    assert table(_download(client)) == table(values)  # the table does not change once read


def test_a_parameter_reads_the_same_by_index_and_by_id(client):
    by_name = _read(client, "WPNAV_SPEED")
    assert by_name is not None and by_name.param_value == pytest.approx(100.0)  # cm/s
    by_index = _read(client, index=by_name.param_index)
    assert (by_index.param_id, by_index.param_value) == ("WPNAV_SPEED", by_name.param_value)


def test_a_set_is_echoed_and_kept(client):
    echo = _set(client, "FS_GCS_TIMEOUT", 7.5)
    assert echo is not None and echo.param_value == 7.5
    assert _read(client, "FS_GCS_TIMEOUT").param_value == 7.5


@pytest.mark.parametrize(
    ("name", "value", "kind", "reason"),
    [
        ("SIM_SPEEDUP", 10.0, mavlink2.MAV_PARAM_TYPE_REAL32, "the run's clock"),
        ("SIM_RATE_HZ", 4.0, mavlink2.MAV_PARAM_TYPE_INT32, "set it in the scenario"),
        ("FS_GCS_TIMEOUT", math.nan, mavlink2.MAV_PARAM_TYPE_REAL32, "finite"),
        ("FS_GCS_TIMEOUT", 1e6, mavlink2.MAV_PARAM_TYPE_REAL32, "must be in"),
        ("FS_GCS_TIMEOUT", 5.0, 0, "param type 0 unknown"),
        ("SIM_GPS1_ENABLE", 0.5, mavlink2.MAV_PARAM_TYPE_REAL32, "whole number"),
    ],
    ids=["read-only", "long-refusal", "nan", "out-of-range", "no-type", "integer-not-whole"],
)
def test_a_refused_set_is_echoed_unchanged_and_said_why(client, name, value, kind, reason):
    before = _read(client, name).param_value
    echo = _set(client, name, value, kind)
    assert echo is not None and echo.param_value == before
    said = _said(client, name)
    assert said and reason in said[-1], said


@pytest.mark.parametrize("kind", range(1, 11), ids=lambda k: f"type-{k}")
def test_any_number_type_sets_an_integer_and_a_float_parameter(client, kind):
    """As ArduPilot: the PARAM_SET's type is not the parameter's to match; its value (C-cast)
    is converted. Each MAV_PARAM_TYPE sets SIM_GPS1_ENABLE (INT32) and FS_GCS_TIMEOUT
    (REAL32), and the echo keeps the parameter's own type."""
    for name, value, other in (("SIM_GPS1_ENABLE", 0.0, 1.0), ("FS_GCS_TIMEOUT", 9.0, 5.0)):
        echo = _set(client, name, value, kind)
        assert echo is not None and echo.param_value == value, _said(client, name)
        expected = _read(client, name).param_type
        assert echo.param_type == expected
        assert _set(client, name, other, kind).param_value == other


def test_pymavlinks_mavset_sets_an_integer_parameter_as_real32(vehicle):
    """``mavparm.MAVParmDict().mavset`` with its default type (REAL32), as ``param set
    SIM_GPS1_ENABLE 0`` from a MAVProxy that has not fetched the list sends it."""
    from pymavlink import mavparm, mavutil

    address = "udpout:{}:{}".format(*vehicle.address)
    master = mavutil.mavlink_connection(address, source_system=255, dialect="ardupilotmega")
    try:
        master.mav.heartbeat_send(6, 8, 0, 0, 0)
        master.target_system = SYSID
        assert mavparm.MAVParmDict().mavset(master, "SIM_GPS1_ENABLE", 0, retries=3)
        master.param_fetch_one("SIM_GPS1_ENABLE")
        value = master.recv_match(type="PARAM_VALUE", blocking=True, timeout=2.0)
        assert value is not None and value.param_value == 0.0
        master.param_set_send("SIM_GPS1_ENABLE", 1.0)
    finally:
        master.close()


def test_an_unknown_id_is_said_and_gets_no_value(client):
    assert _set(client, "NO_SUCH_PARAM", 1.0) is None
    assert _said(client, "NO_SUCH_PARAM")


def _said(client: MavClient, name: str) -> list[str]:
    """The STATUSTEXTs about ``name`` that have come (before or after its echo), long ones
    put together from their chunks."""
    client.collect(0.2)
    chunks, texts = StatusChunks(), []
    for message in client.seen:
        if message.get_type() == "STATUSTEXT" and (text := chunks.add(message)) is not None:
            texts.append(text)
    return [text for text in texts if name in text]


def test_link_loss_set_live_thins_what_the_vehicle_sends():
    """SIM_LINK_LOSS reaches the process's socket: about half of what it sends is lost at 0.5
    (the echo of the set itself may be, so it is sent until one comes back)."""
    with vehicle_process("support-1", "--speedup", "8") as running:
        client = MavClient(running.address)
        try:
            assert _read(client, "SIM_LINK_LOSS").param_value == 0.0
            before = len(client.collect(1.5))
            echo = None
            for _ in range(20):
                echo = echo or _set(client, "SIM_LINK_LOSS", 0.5)
            assert echo is not None and echo.param_value == 0.5
            after = len(client.collect(1.5))
        finally:
            client.close()
    assert 0.25 < after / before < 0.75, (before, after)
