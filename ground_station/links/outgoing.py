"""Builders of the MAVLink messages the ground station sends (pymavlink's generated classes
only): the mirror of :mod:`vehicle_sim.mavlink.telemetry`."""

from __future__ import annotations

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.world.frames import enu_to_ned

GCS_SYSTEM_ID = 255
GCS_COMPONENT_ID = 190
POSITION_ONLY = 0b0000_1101_1111_1000  # SET_POSITION_TARGET type_mask: position, no yaw
POSITION_VELOCITY = 0b0000_1101_1100_0000  # ... position and velocity, no yaw
GUIDED_AND_ARMED = (  # DO_SET_MODE custom mode 4 (GUIDED), then arm
    (mavlink2.MAV_CMD_DO_SET_MODE, (1, 4)),
    (mavlink2.MAV_CMD_COMPONENT_ARM_DISARM, (1,)),
)


def gcs_heartbeat() -> mavlink2.MAVLink_heartbeat_message:
    """The HEARTBEAT of a ground station."""
    return mavlink2.MAVLink_heartbeat_message(
        mavlink2.MAV_TYPE_GCS, mavlink2.MAV_AUTOPILOT_INVALID, 0, 0, 0, 3
    )


def clock_tick(epoch_unix_s: float, target_ms: int) -> mavlink2.MAVLink_system_time_message:
    """The lockstep clock's tick: SYSTEM_TIME asking the vehicles to advance to ``target_ms``."""
    usec = round((epoch_unix_s + target_ms / 1000.0) * 1e6)
    return mavlink2.MAVLink_system_time_message(usec, target_ms)


def vision_position_estimate(
    position_enu: np.ndarray, time_usec: int
) -> mavlink2.MAVLink_vision_position_estimate_message:
    """The position estimate a vehicle's autopilot navigates on (NED from the anchor)."""
    n, e, d = (float(v) for v in enu_to_ned(position_enu))
    return mavlink2.MAVLink_vision_position_estimate_message(time_usec, n, e, d, 0, 0, 0)


def position_target(
    target_enu: np.ndarray,
    time_boot_ms: int,
    system_id: int,
    velocity_enu: np.ndarray | None = None,
) -> mavlink2.MAVLink_set_position_target_local_ned_message:
    """A SET_POSITION_TARGET_LOCAL_NED (LOCAL_NED, origin at the anchor): a position, or a
    position and the velocity it moves on at (the autopilot's feed-forward)."""
    n, e, d = (float(v) for v in enu_to_ned(target_enu))
    mask, velocity = POSITION_ONLY, [0.0, 0.0, 0.0]
    if velocity_enu is not None:
        mask, velocity = POSITION_VELOCITY, [float(v) for v in enu_to_ned(velocity_enu)]
    return mavlink2.MAVLink_set_position_target_local_ned_message(
        time_boot_ms,
        system_id,
        1,
        mavlink2.MAV_FRAME_LOCAL_NED,
        mask,
        n,
        e,
        d,
        *velocity,
        *[0] * 5,
    )


def mission_set_current(system_id: int, seq: int) -> mavlink2.MAVLink_mission_set_current_message:
    """MISSION_SET_CURRENT: the vehicle's current mission item becomes ``seq``."""
    return mavlink2.MAVLink_mission_set_current_message(system_id, 1, seq)


def command_long(
    system_id: int, command: int, params: tuple[float, ...]
) -> mavlink2.MAVLink_command_long_message:
    """COMMAND_LONG to component 1 with up to seven parameters (the rest zero)."""
    values = [*params, *[0.0] * (7 - len(params))]
    return mavlink2.MAVLink_command_long_message(system_id, 1, command, 0, *values)


def timesync_request(now_ns: int) -> mavlink2.MAVLink_timesync_message:
    """A TIMESYNC request (tc1 = 0) stamped with the ground station's time in nanoseconds."""
    return mavlink2.MAVLink_timesync_message(0, now_ns)
