"""What a vehicle does with each message from a ground station besides the mission and
parameter protocols: setpoints, the navigation estimate, commands, SET_MODE, TIMESYNC.

Each handler takes the :class:`~vehicle_sim.vehicle.Vehicle` and the message, and never raises
on bad content (it is counted and, where a pilot would want to know, said once).
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable
from typing import Any

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.world.frames import ned_to_enu
from vehicle_sim.mavlink import modes
from vehicle_sim.mavlink.commands import execute, set_mode
from vehicle_sim.mavlink.guidance import (
    MAX_ABS_COORD_M,
    geofence_problem,
    setpoint_problem,
    setpoint_velocity,
)

WARNING_REPEAT_S = 5.0
ESTIMATE_RESTART_S = 2.0  # an estimate stamped further back than this is a sender restarted


def on_setpoint(vehicle: Any, msg: Any) -> None:
    """SET_POSITION_TARGET_LOCAL_NED: a new target, unless it is refused (then, if the fence
    refused it, the vehicle stops where it is). The same setpoint again with the same stamp
    (a datagram sent again, or delivered twice) is ignored: taken after the vehicle has
    stepped, its fence check would start from a later belief. An unstamped one is always
    taken."""
    if vehicle.crashed:
        vehicle.counters.reject("setpoint: crashed")
        return
    if _repeated_setpoint(vehicle, msg):
        vehicle.counters.reject("setpoint: repeated")
        return
    problem = setpoint_problem(msg, vehicle.armed and vehicle.mode == modes.GUIDED)
    target = ned_to_enu(np.array([msg.x, msg.y, msg.z], dtype=float))
    kinematics = vehicle.kinematics
    if problem is None:
        problem = geofence_problem(vehicle.world, kinematics.believed, target)
        if problem is not None:  # a guided vehicle told to leave the fence stops there
            kinematics.hold()
    if problem is not None:
        category, detail = problem
        vehicle.counters.reject(f"setpoint: {category}")
        warn_once(vehicle, f"Setpoint rejected: {detail}")
        return
    kinematics.target = target
    kinematics.target_velocity = setpoint_velocity(msg, vehicle.speed_limit_m_s)
    vehicle.last_setpoint_s = vehicle.sim_time_s
    if vehicle.failsafe:
        vehicle.failsafe = False
        vehicle.notify(mavlink2.MAV_SEVERITY_NOTICE, "Failsafe cleared: setpoints resumed")


def _repeated_setpoint(vehicle: Any, msg: Any) -> bool:
    """Whether this stamped setpoint is its sender's last one again (noting it if not)."""
    stamp = int(msg.time_boot_ms)
    if not stamp:
        return False
    sender = (msg.get_srcSystem(), msg.get_srcComponent())
    seen = (stamp, msg.type_mask, msg.coordinate_frame, msg.x, msg.y, msg.z, msg.vx, msg.vy, msg.vz)
    if vehicle.last_setpoint_seen.get(sender) == seen:
        return True
    vehicle.last_setpoint_seen[sender] = seen
    return False


def warn_once(vehicle: Any, text: str) -> None:
    """A warning STATUSTEXT, not repeated while the same problem persists (5 s)."""
    last_text, last_s = vehicle.last_warning
    if text != last_text or vehicle.sim_time_s - last_s >= WARNING_REPEAT_S:
        vehicle.notify(mavlink2.MAV_SEVERITY_WARNING, text)
        vehicle.last_warning = (text, vehicle.sim_time_s)


def on_vision_estimate(vehicle: Any, msg: Any) -> None:
    """VISION_POSITION_ESTIMATE: the position the autopilot believes from now on, unless its
    sender already gave one stamped as late or later, by less than ``ESTIMATE_RESTART_S`` (a
    datagram delivered twice over a lossy link, or overtaken: taken after the vehicle has
    moved on, it would set the belief back). A stamp further back is a sender that started
    again (a ground station restarted against running vehicles): taken, and said once. An
    estimate stamped 0 is unstamped and always taken."""
    values = (msg.x, msg.y, msg.z)
    if not all(math.isfinite(v) and abs(v) < MAX_ABS_COORD_M for v in values):
        vehicle.counters.reject("estimate out of range")
        return
    sender, stamp = (msg.get_srcSystem(), msg.get_srcComponent()), int(msg.usec)
    last = vehicle.last_estimate_usec.get(sender)
    if stamp and last is not None and stamp <= last:
        if last - stamp < ESTIMATE_RESTART_S * 1e6:
            vehicle.counters.reject("estimate not newer than the last")
            return
        back_s = (last - stamp) / 1e6
        vehicle.notify(
            mavlink2.MAV_SEVERITY_NOTICE, f"Estimates restarted: stamps {back_s:.1f} s back"
        )
    if stamp:
        vehicle.last_estimate_usec[sender] = stamp
    vehicle.kinematics.set_estimate(ned_to_enu(np.array(values, dtype=float)))


def on_command(vehicle: Any, msg: Any) -> None:
    """COMMAND_LONG or COMMAND_INT, answered by COMMAND_ACK."""
    params = [msg.param1, msg.param2, msg.param3, msg.param4]
    if msg.get_type() == "COMMAND_LONG":
        params += [msg.param5, msg.param6, msg.param7]
    else:
        params += [msg.x, msg.y, msg.z]
    try:
        result = execute(vehicle, int(msg.command), params)
    except (struct.error, OverflowError, ValueError):  # a value no reply could carry
        result = mavlink2.MAV_RESULT_FAILED  # answered all the same, as ArduPilot does
    vehicle.send(
        mavlink2.MAVLink_command_ack_message(
            msg.command, result, 0, 0, msg.get_srcSystem(), msg.get_srcComponent()
        )
    )


def on_set_mode(vehicle: Any, msg: Any) -> None:
    """SET_MODE, answered by COMMAND_ACK as ArduPilot answers it."""
    result = set_mode(vehicle, int(msg.base_mode), int(msg.custom_mode))
    vehicle.send(
        mavlink2.MAVLink_command_ack_message(
            mavlink2.MAVLINK_MSG_ID_SET_MODE,
            result,
            0,
            0,
            msg.get_srcSystem(),
            msg.get_srcComponent(),
        )
    )


def on_timesync(vehicle: Any, msg: Any) -> None:
    """TIMESYNC: a request is answered with the simulated time."""
    if msg.tc1 == 0:
        now_ns = round(vehicle.sim_time_s * 1e9)
        vehicle.send(mavlink2.MAVLink_timesync_message(now_ns, msg.ts1))


HANDLERS: dict[str, Callable[[Any, Any], None]] = {
    "SET_POSITION_TARGET_LOCAL_NED": on_setpoint,
    "VISION_POSITION_ESTIMATE": on_vision_estimate,
    "COMMAND_LONG": on_command,
    "COMMAND_INT": on_command,
    "SET_MODE": on_set_mode,
    "TIMESYNC": on_timesync,
}
