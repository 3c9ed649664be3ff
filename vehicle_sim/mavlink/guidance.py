"""Which position targets a guided vehicle accepts: the message's own form, then the fence."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.world.model import KnownWorld

POSITION_ONLY_MASK_REQUIRED = 0b0000_0001_1111_1000  # velocity + acceleration ignored
POSITION_BITS = 0b0000_0000_0000_0111
FORCE_BIT = 0b0000_0010_0000_0000
MAX_ABS_COORD_M = 100_000.0


def setpoint_problem(msg: Any, guided: bool) -> tuple[str, str] | None:
    """(category, detail) of what is wrong with a SET_POSITION_TARGET_LOCAL_NED for a vehicle
    that is (``guided``) or is not armed in GUIDED, or None."""
    if msg.coordinate_frame != mavlink2.MAV_FRAME_LOCAL_NED:
        return "frame", f"frame {msg.coordinate_frame}, LOCAL_NED only"
    mask = int(msg.type_mask)
    ignores_motion = (mask & POSITION_ONLY_MASK_REQUIRED) == POSITION_ONLY_MASK_REQUIRED
    if mask & POSITION_BITS or not ignores_motion or mask & FORCE_BIT:
        return "type_mask", f"type_mask {mask}, position targets only"
    values = (msg.x, msg.y, msg.z)
    if not all(math.isfinite(v) and abs(v) < MAX_ABS_COORD_M for v in values):
        return "out of range", "position out of range"
    if not guided:
        return "not guided", "not armed in GUIDED"
    return None


def geofence_problem(
    world: KnownWorld, believed: np.ndarray, target: np.ndarray
) -> tuple[str, str] | None:
    """Targets outside the workspace, inside the structure, or reached from ``believed`` (the
    autopilot fences in its own navigation frame) only through the structure."""
    problem = world.placement_problem(target)
    if problem is not None:
        return "geofence", f"fence: {problem}"
    structure = world.structure
    if (
        np.linalg.norm(target - believed) > 0
        and structure.segments_blocked(believed[None], target[None])[0]
    ):
        return "geofence", "fence: crosses structure"
    return None
