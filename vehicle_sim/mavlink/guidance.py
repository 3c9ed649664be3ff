"""Which position targets a guided vehicle accepts: the message's own form, then the fence.

A target is a position, or a position and a velocity (ArduPilot's GUIDED takes both: the
target then moves on at that velocity, at most the vehicle's speed limit, which the autopilot
also feeds forward, until the next setpoint, the failsafe, or the fence: a target that would
move outside it stops where it is). Acceleration, force, yaw and yaw rate are not taken."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.world.frames import ned_to_enu
from mission.world.model import KnownWorld

ACCELERATION_BITS = 0b0000_0001_1100_0000  # ignored, always
VELOCITY_BITS = 0b0000_0000_0011_1000  # all ignored, or none
POSITION_BITS = 0b0000_0000_0000_0111
MAX_SETPOINT_SPEED_M_S = 50.0
SPEED_ROUNDING = 1e-5  # a velocity sent as float32 at the speed limit arrives ~5e-7 over it
FORCE_BIT = 0b0000_0010_0000_0000
MAX_ABS_COORD_M = 100_000.0


def setpoint_problem(msg: Any, guided: bool) -> tuple[str, str] | None:
    """(category, detail) of what is wrong with a SET_POSITION_TARGET_LOCAL_NED for a vehicle
    that is (``guided``) or is not armed in GUIDED, or None."""
    if msg.coordinate_frame != mavlink2.MAV_FRAME_LOCAL_NED:
        return "frame", f"frame {msg.coordinate_frame}, LOCAL_NED only"
    mask = int(msg.type_mask)
    ignores_acceleration = (mask & ACCELERATION_BITS) == ACCELERATION_BITS
    velocity_bits = mask & VELOCITY_BITS
    if (
        mask & POSITION_BITS
        or not ignores_acceleration
        or velocity_bits not in (0, VELOCITY_BITS)
        or mask & FORCE_BIT
    ):
        return "type_mask", f"type_mask {mask}, position (and velocity) targets only"
    values = (msg.x, msg.y, msg.z)
    if not all(math.isfinite(v) and abs(v) < MAX_ABS_COORD_M for v in values):
        return "out of range", "position out of range"
    if velocity_bits == 0 and not all(
        math.isfinite(v) and abs(v) <= MAX_SETPOINT_SPEED_M_S for v in (msg.vx, msg.vy, msg.vz)
    ):
        return "out of range", "velocity out of range"
    if not guided:
        return "not guided", "not armed in GUIDED"
    return None


def setpoint_velocity(msg: Any, speed_limit_m_s: float) -> np.ndarray | None:
    """The velocity (ENU) of an accepted setpoint, no faster than the vehicle's speed limit;
    None for a position-only one."""
    if int(msg.type_mask) & VELOCITY_BITS:
        return None
    velocity = ned_to_enu(np.array([msg.vx, msg.vy, msg.vz], dtype=float))
    speed = float(np.linalg.norm(velocity))
    if speed > speed_limit_m_s * (1 + SPEED_ROUNDING):  # a plan's own speed passes untouched
        velocity *= speed_limit_m_s / speed
    return velocity


def geofence_problem(
    world: KnownWorld, believed: np.ndarray, target: np.ndarray
) -> tuple[str, str] | None:
    """Targets outside the workspace, inside the structure, or reached from ``believed`` (the
    autopilot fences in its own navigation frame) only through the structure."""
    problem = world.placement_problem(target)
    if problem is not None:
        return "geofence", f"fence: {problem}"
    structure = world.structure
    if np.linalg.norm(target - believed) > 0 and structure.segment_blocked(believed, target):
        return "geofence", "fence: crosses structure"
    return None


def fence_moving_target(world: KnownWorld, kinematics: Any, step_s: float) -> None:
    """A target moving at its setpoint's velocity stops where it is if the step would take it
    outside the fence (the vehicle then holds it)."""
    if kinematics.target is None or kinematics.target_velocity is None:
        return
    ahead = kinematics.target + kinematics.target_velocity * step_s
    if geofence_problem(world, kinematics.target, ahead) is not None:
        kinematics.target_velocity = None
