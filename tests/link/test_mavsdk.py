"""MAVSDK, a real client library from PyPI, against one vehicle process: its Param plugin gets a
float and an integer parameter by name (ArduPilot's C-cast encoding taken as such), sets one the
vehicle then holds, gets an error (and leaves the value alone) when the vehicle refuses a set,
and lists every parameter; its Failure plugin is denied until SIM_FAIL_ENABLE allows failure
injection, then turns the GPS off and back on. A pymavlink-level client on a second socket
checks each effect independently.

MAVSDK >= 4 is the native binding (the C++ library in-process through ctypes, no mavsdk_server
and no gRPC); it reaches the vehicle with ``udpout://``, as MAVProxy does with ``udpout:``."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import pytest
from mavsdk import ComponentType, Configuration, ConnectionResult, Mavsdk
from mavsdk.plugins.failure import Failure, FailureError, FailureResult, FailureType, FailureUnit
from mavsdk.plugins.param import Param, ParamError
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from tests.mav_client import MavClient
from tests.processes import VehicleProcess, vehicle_process

pytestmark = pytest.mark.slow  # a vehicle process
SYSID = 2  # support-1
SPEEDUP = 10.0  # GPS fixes come ten times as often
GCS_HEARTBEAT = mavlink2.MAVLink_heartbeat_message(
    mavlink2.MAV_TYPE_GCS, mavlink2.MAV_AUTOPILOT_INVALID, 0, 0, mavlink2.MAV_STATE_ACTIVE, 3
)


@dataclass
class Link:
    """The vehicle, MAVSDK's plugins of it, and an independent pymavlink-level observer."""

    vehicle: VehicleProcess
    param: Param
    failure: Failure
    observer: MavClient


@pytest.fixture
def link() -> Iterator[Link]:
    """One vehicle and a MAVSDK connected to it, both gone after the test, pass or fail."""
    with vehicle_process("support-1", "--speedup", f"{SPEEDUP:g}") as vehicle:
        sdk = Mavsdk(Configuration.create_with_component_type(ComponentType.GROUND_STATION))
        observer = MavClient(vehicle.address)
        try:
            connected = sdk.add_any_connection(f"udpout://127.0.0.1:{vehicle.port}")
            assert connected == ConnectionResult.SUCCESS
            system = sdk.first_autopilot(10.0)
            assert system is not None, "MAVSDK found no autopilot within 10 s"
            observer.send(GCS_HEARTBEAT)  # the vehicle streams to every peer that talked to it
            yield Link(vehicle, Param(system), Failure(system), observer)
        finally:
            observer.close()
            sdk.destroy()  # stops MAVSDK's threads and closes its socket


def _read(observer: MavClient, name: str):
    """The vehicle's PARAM_VALUE of ``name``, read by id with pymavlink (not MAVSDK)."""
    observer.collect(0.1)  # values MAVSDK's requests had the vehicle send us too
    observer.send(mavlink2.MAVLink_param_request_read_message(SYSID, 1, name.encode(), -1))
    value = observer.wait_for("PARAM_VALUE", 3.0, where=lambda m: m.param_id == name)
    assert value is not None, f"no PARAM_VALUE of {name}"
    return value


def _listed(observer: MavClient) -> dict[str, object]:
    """Every parameter's PARAM_VALUE by PARAM_REQUEST_LIST with pymavlink, by name."""
    observer.collect(0.1)
    observer.send(mavlink2.MAVLink_param_request_list_message(SYSID, 1))
    first = observer.wait_for("PARAM_VALUE", 3.0)
    assert first is not None, "no answer to PARAM_REQUEST_LIST"
    values = {first.param_id: first}
    values.update((m.param_id, m) for m in observer.collect(0.5) if m.get_type() == "PARAM_VALUE")
    assert len(values) == first.param_count, "the list came whole over loopback"
    return values


def _fixes(observer: MavClient, seconds: float) -> int:
    """How many GPS_RAW_INT the observer gets within ``seconds`` (after a short settling)."""
    observer.collect(0.3)  # whatever was already on its way
    return sum(m.get_type() == "GPS_RAW_INT" for m in observer.collect(seconds))


def test_mavsdk_gets_parameters_of_both_types_by_name(link):
    timeout = link.param.get_param_float("FS_GCS_TIMEOUT")
    assert timeout > 0 and timeout == _read(link.observer, "FS_GCS_TIMEOUT").param_value
    enabled = link.param.get_param_int("SIM_FAIL_ENABLE")
    assert enabled == 0 and isinstance(enabled, int)
    wire = _read(link.observer, "SIM_FAIL_ENABLE")
    assert wire.param_type == mavlink2.MAV_PARAM_TYPE_INT32 and wire.param_value == 0.0
    with pytest.raises(ParamError):  # the type comes from the vehicle's PARAM_VALUE
        link.param.get_param_int("FS_GCS_TIMEOUT")


def test_mavsdk_sets_an_integer_parameter_the_vehicle_then_holds(link):
    link.param.set_param_int("SIM_FAIL_ENABLE", 1)
    assert link.param.get_param_int("SIM_FAIL_ENABLE") == 1
    wire = _read(link.observer, "SIM_FAIL_ENABLE")
    assert wire.param_value == 1.0 and wire.param_type == mavlink2.MAV_PARAM_TYPE_INT32


@pytest.mark.parametrize(
    ("name", "value"),
    [("SIM_SPEEDUP", 2.0), ("SIM_FAIL_ENABLE", 5)],  # read-only; out of range [0, 1]
    ids=["read-only", "out-of-range"],
)
def test_a_set_the_vehicle_refuses_is_an_error_in_mavsdk_and_changes_nothing(link, name, value):
    """The vehicle answers a refused PARAM_SET with its unchanged PARAM_VALUE (and a
    STATUSTEXT); MAVSDK sends the set again on a value that does not match, five more times,
    then raises ParamError (TIMEOUT, though the vehicle answered every try at once)."""
    before = _read(link.observer, name).param_value
    setter = link.param.set_param_float if isinstance(value, float) else link.param.set_param_int
    with pytest.raises(ParamError) as refused:
        setter(name, value)
    assert refused.value.result.name in {"TIMEOUT", "READ_ONLY", "VALUE_OUT_OF_RANGE"}
    assert _read(link.observer, name).param_value == before
    getter = link.param.get_param_float if isinstance(value, float) else link.param.get_param_int
    assert getter(name) == before


def test_mavsdk_lists_every_parameter_with_the_vehicle_s_values(link):
    every = link.param.get_all_params()
    assert not every.custom_params
    by_mavsdk = {p.name: float(p.value) for p in every.int_params + every.float_params}
    count = _read(link.observer, "SIM_FAIL_ENABLE").param_count
    assert len(by_mavsdk) == len(every.int_params) + len(every.float_params) == count
    listed = _listed(link.observer)
    assert by_mavsdk == {name: m.param_value for name, m in listed.items()}
    real = {name for name, m in listed.items() if m.param_type == mavlink2.MAV_PARAM_TYPE_REAL32}
    assert {p.name for p in every.float_params} == real  # the rest are integers, C-cast


def test_mavsdk_injects_a_gps_failure_once_the_vehicle_allows_it(link):
    gps = FailureUnit.SENSOR_GPS
    with pytest.raises(FailureError) as refused:
        link.failure.inject(gps, FailureType.OFF, 0)
    assert refused.value.result == FailureResult.DENIED  # MAV_RESULT_DENIED: not enabled
    assert _fixes(link.observer, 1.0) > 0, "GPS_RAW_INT flows while the inject is refused"

    link.param.set_param_int("SIM_FAIL_ENABLE", 1)
    with pytest.raises(FailureError) as unsupported:
        link.failure.inject(FailureUnit.SYSTEM_MOTOR, FailureType.OFF, 0)
    assert unsupported.value.result == FailureResult.UNSUPPORTED

    link.failure.inject(gps, FailureType.OFF, 0)  # returns: MAV_RESULT_ACCEPTED
    assert _fixes(link.observer, 1.0) == 0, "no GPS_RAW_INT while the GPS is off"

    link.failure.inject(gps, FailureType.OK, 0)
    assert _fixes(link.observer, 1.0) >= 3, "GPS_RAW_INT is back"
