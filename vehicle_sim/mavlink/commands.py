"""COMMAND_LONG / COMMAND_INT handling: each command returns a MAV_RESULT."""

from __future__ import annotations

import math
from typing import Any, Protocol

from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from vehicle_sim.mavlink import modes
from vehicle_sim.mavlink.mission_server import MissionServer
from vehicle_sim.mavlink.param_server import ParamServer
from vehicle_sim.mavlink.stream_schedule import StreamSchedule


class Vehicle(Protocol):
    """What the commands act on (:class:`vehicle_sim.vehicle.Vehicle`)."""

    schedule: StreamSchedule
    mission: MissionServer

    def send(self, message: Any) -> None: ...
    def arm(self, armed: bool) -> None: ...
    def change_mode(self, mode: int) -> None: ...
    def build_stream(self, message_id: int, work_truth: Any = None) -> Any: ...
    def notify(self, severity: int, text: str) -> None: ...
    def inject_failure(self, unit: int, kind: int) -> bool: ...

    params: ParamServer


ACCEPTED = mavlink2.MAV_RESULT_ACCEPTED
DENIED = mavlink2.MAV_RESULT_DENIED
UNSUPPORTED = mavlink2.MAV_RESULT_UNSUPPORTED
FAILED = mavlink2.MAV_RESULT_FAILED
REQUESTABLE_ONCE = (mavlink2.MAVLINK_MSG_ID_AUTOPILOT_VERSION,)
MAX_INTERVAL_ID = 0xFFFF  # MESSAGE_INTERVAL.message_id is a uint16
MAX_INTERVAL_US = 2**31 - 1  # and its interval_us an int32


def execute(vehicle: Vehicle, command: int, params: list[float]) -> int:
    """Carry out one command and return its MAV_RESULT."""
    handler = _COMMANDS.get(command)
    if handler is None:
        return UNSUPPORTED
    if any(math.isinf(p) for p in params):
        return DENIED
    return handler(vehicle, params)


def set_mode(vehicle: Vehicle, base_mode: int, custom_mode: int) -> int:
    """Switch to the mode a (base_mode, custom_mode) pair names."""
    if not base_mode & mavlink2.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED:
        return DENIED
    mode = modes.parse_custom_mode(custom_mode)
    if mode is None:
        return DENIED
    vehicle.change_mode(mode)
    return ACCEPTED


def _arm(vehicle: Vehicle, params: list[float]) -> int:
    if params[0] not in (0.0, 1.0):
        return DENIED
    if params[0] == 1.0 and vehicle.crashed:  # a crashed vehicle does not fly again
        return DENIED
    vehicle.arm(params[0] == 1.0)
    return ACCEPTED


def _do_set_mode(vehicle: Vehicle, params: list[float]) -> int:
    if math.isnan(params[0]) or math.isnan(params[1]):
        return DENIED
    return set_mode(vehicle, int(params[0]), int(params[1]))


def _interval_id(value: float) -> int | None:
    """A message id MESSAGE_INTERVAL can carry, or None."""
    if math.isnan(value) or value != int(value) or not 0 <= value <= MAX_INTERVAL_ID:
        return None
    return int(value)


def _set_interval(vehicle: Vehicle, params: list[float]) -> int:
    message_id = _interval_id(params[0])
    if message_id is None or math.isnan(params[1]) or params[1] > MAX_INTERVAL_US:
        return DENIED  # an interval MESSAGE_INTERVAL could not report back
    return ACCEPTED if vehicle.schedule.set_interval(message_id, params[1]) else UNSUPPORTED


def _get_interval(vehicle: Vehicle, params: list[float]) -> int:
    message_id = _interval_id(params[0])
    if message_id is None:
        return DENIED
    if message_id not in vehicle.schedule.intervals_s:
        vehicle.send(mavlink2.MAVLink_message_interval_message(message_id, 0))
        return ACCEPTED
    interval = vehicle.schedule.intervals_s[message_id]
    vehicle.send(
        mavlink2.MAVLink_message_interval_message(
            message_id, -1 if interval is None else round(interval * 1e6)
        )
    )
    return ACCEPTED


def _request_message(vehicle: Vehicle, params: list[float]) -> int:
    if math.isnan(params[0]):
        return DENIED
    message_id = int(params[0])
    if message_id not in vehicle.schedule.intervals_s and message_id not in REQUESTABLE_ONCE:
        return UNSUPPORTED
    if message_id == mavlink2.MAVLINK_MSG_ID_LANDING_TARGET:
        return DENIED  # a camera sample needs the step's truth; it comes with the stream
    message = vehicle.build_stream(message_id)
    if message is None:
        return FAILED  # the sensor is failed off
    vehicle.send(message)
    return ACCEPTED


def _inject_failure(vehicle: Vehicle, params: list[float]) -> int:
    """MAV_CMD_INJECT_FAILURE: param1 the unit, param2 the type (vehicle_sim.sensors.failures)."""
    if math.isnan(params[0]) or math.isnan(params[1]):
        return DENIED
    if not vehicle.params.table.value("SIM_FAIL_ENABLE"):
        return DENIED  # failure injection is off, as PX4's SYS_FAILURE_EN gates it
    if not vehicle.inject_failure(int(params[0]), int(params[1])):
        return UNSUPPORTED
    return ACCEPTED


def _request_capabilities(vehicle: Vehicle, params: list[float]) -> int:
    vehicle.send(vehicle.build_stream(mavlink2.MAVLINK_MSG_ID_AUTOPILOT_VERSION))
    return ACCEPTED


def _set_mission_current(vehicle: Vehicle, params: list[float]) -> int:
    if math.isnan(params[0]) or not vehicle.mission.set_current(int(params[0])):
        return DENIED
    vehicle.mission.send_current()
    return ACCEPTED


_COMMANDS = {
    mavlink2.MAV_CMD_COMPONENT_ARM_DISARM: _arm,
    mavlink2.MAV_CMD_DO_SET_MODE: _do_set_mode,
    mavlink2.MAV_CMD_SET_MESSAGE_INTERVAL: _set_interval,
    mavlink2.MAV_CMD_GET_MESSAGE_INTERVAL: _get_interval,
    mavlink2.MAV_CMD_REQUEST_MESSAGE: _request_message,
    mavlink2.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES: _request_capabilities,
    mavlink2.MAV_CMD_DO_SET_MISSION_CURRENT: _set_mission_current,
    mavlink2.MAV_CMD_INJECT_FAILURE: _inject_failure,
}
