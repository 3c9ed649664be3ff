"""One message of a vehicle's streams, built for its current state (sensors sampled when the
message carries a measurement)."""

from __future__ import annotations

from typing import Any

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from vehicle_sim.mavlink import telemetry


def build(vehicle: Any, message_id: int, work_truth: np.ndarray | None = None) -> Any:
    """Build one message of a stream for the current state of ``vehicle`` (a
    :class:`~vehicle_sim.vehicle.Vehicle`, which calls this); None where a failed sensor
    publishes nothing (:mod:`~vehicle_sim.sensors.failures`)."""
    k, clock = vehicle.kinematics, vehicle.clock
    if message_id == mavlink2.MAVLINK_MSG_ID_SIM_STATE:
        return telemetry.sim_state(k.truth, k.velocity, vehicle.frame, _attitude(k))
    if message_id == mavlink2.MAVLINK_MSG_ID_ATTITUDE:
        attitude = _attitude(k)
        return (
            None if attitude is None else telemetry.attitude_message(attitude, clock.time_boot_ms)
        )
    if message_id == mavlink2.MAVLINK_MSG_ID_LOCAL_POSITION_NED:
        return telemetry.local_position_ned(k.believed, k.velocity, clock.time_boot_ms)
    if message_id == mavlink2.MAVLINK_MSG_ID_GLOBAL_POSITION_INT:
        return telemetry.global_position_int(
            k.believed, k.velocity, np.zeros(3), vehicle.frame, clock.time_boot_ms
        )
    if message_id == mavlink2.MAVLINK_MSG_ID_GPS_RAW_INT:
        return vehicle.gnss.reading(k.truth, clock.time_unix_usec)
    if message_id == mavlink2.MAVLINK_MSG_ID_LANDING_TARGET:
        return vehicle.camera.reading(k.truth, work_truth, clock.time_unix_usec)
    if message_id == mavlink2.MAVLINK_MSG_ID_HEARTBEAT:
        return vehicle.heartbeat()
    if message_id == mavlink2.MAVLINK_MSG_ID_SYS_STATUS:
        return telemetry.sys_status(vehicle.counters.bad_packets)
    if message_id == mavlink2.MAVLINK_MSG_ID_MISSION_CURRENT:
        state = (
            mavlink2.MISSION_STATE_NO_MISSION
            if not vehicle.mission.items
            else mavlink2.MISSION_STATE_ACTIVE
        )
        return mavlink2.MAVLink_mission_current_message(
            vehicle.mission.current, len(vehicle.mission.items), state, 0
        )
    if message_id == mavlink2.MAVLINK_MSG_ID_AUTOPILOT_VERSION:
        return telemetry.autopilot_version(vehicle.identity.system_id)
    raise KeyError(message_id)


def _attitude(motion: Any) -> telemetry.Attitude | None:
    """A flying body's attitude and rates (None for the kinematic point, which has none)."""
    quaternion, rates = getattr(motion, "attitude", None), getattr(motion, "rates", None)
    if quaternion is None or rates is None:
        return None
    return telemetry.Attitude.of(quaternion, rates)
