"""Mission items as MAVLink carries them, shared by the vehicle and the ground station."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

MISSION = mavlink2.MAV_MISSION_TYPE_MISSION
GLOBAL_FRAMES = {
    mavlink2.MAV_FRAME_GLOBAL,
    mavlink2.MAV_FRAME_GLOBAL_RELATIVE_ALT,
    mavlink2.MAV_FRAME_GLOBAL_INT,
    mavlink2.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
}
NAV_POSITION_COMMANDS = {
    mavlink2.MAV_CMD_NAV_WAYPOINT,
    mavlink2.MAV_CMD_NAV_LOITER_UNLIM,
    mavlink2.MAV_CMD_NAV_LOITER_TIME,
    mavlink2.MAV_CMD_NAV_TAKEOFF,
    mavlink2.MAV_CMD_NAV_LAND,
}
OTHER_COMMANDS = {
    mavlink2.MAV_CMD_NAV_RETURN_TO_LAUNCH,
    mavlink2.MAV_CMD_NAV_DELAY,
    mavlink2.MAV_CMD_DO_CHANGE_SPEED,
    mavlink2.MAV_CMD_CONDITION_DELAY,
}


@dataclass(frozen=True)
class MissionItem:
    """One stored item, exactly as MISSION_ITEM_INT carries it (x, y in 1e-7 degrees)."""

    seq: int
    frame: int
    command: int
    current: int
    autocontinue: int
    param1: float
    param2: float
    param3: float
    param4: float
    x: int
    y: int
    z: float

    @classmethod
    def from_message(cls, msg: Any) -> MissionItem:
        """From MISSION_ITEM_INT, or from the float MISSION_ITEM (degrees scaled by 1e7)."""
        if msg.get_type() == "MISSION_ITEM_INT":
            x, y = int(msg.x), int(msg.y)
        else:
            x, y = _degrees_to_e7(msg.x), _degrees_to_e7(msg.y)
        return cls(
            int(msg.seq),
            int(msg.frame),
            int(msg.command),
            int(msg.current),
            int(msg.autocontinue),
            float(msg.param1),
            float(msg.param2),
            float(msg.param3),
            float(msg.param4),
            x,
            y,
            float(msg.z),
        )

    def to_int_message(self, target: tuple[int, int]) -> Any:
        """As MISSION_ITEM_INT addressed to ``target`` (system, component)."""
        return mavlink2.MAVLink_mission_item_int_message(
            target[0],
            target[1],
            self.seq,
            self.frame,
            self.command,
            self.current,
            self.autocontinue,
            self.param1,
            self.param2,
            self.param3,
            self.param4,
            self.x,
            self.y,
            self.z,
            MISSION,
        )

    def to_float_message(self, target: tuple[int, int]) -> Any:
        """As the legacy float MISSION_ITEM."""
        return mavlink2.MAVLink_mission_item_message(
            target[0],
            target[1],
            self.seq,
            self.frame,
            self.command,
            self.current,
            self.autocontinue,
            self.param1,
            self.param2,
            self.param3,
            self.param4,
            self.x / 1e7,
            self.y / 1e7,
            self.z,
            MISSION,
        )


def _degrees_to_e7(value: float) -> int:
    if not math.isfinite(value) or abs(value) > 1000:
        return 2**31 - 1  # out of range: validation rejects it
    return round(value * 1e7)


def check_item(item: MissionItem) -> int:
    """MAV_MISSION_ACCEPTED, or the MAV_MISSION_RESULT error that rejects the item."""
    if item.command not in NAV_POSITION_COMMANDS | OTHER_COMMANDS:
        return mavlink2.MAV_MISSION_UNSUPPORTED
    if item.command in NAV_POSITION_COMMANDS:
        if item.frame not in GLOBAL_FRAMES:
            return mavlink2.MAV_MISSION_UNSUPPORTED_FRAME
        if not -900_000_000 <= item.x <= 900_000_000:
            return mavlink2.MAV_MISSION_INVALID_PARAM5_X
        if not -1_800_000_000 <= item.y <= 1_800_000_000:
            return mavlink2.MAV_MISSION_INVALID_PARAM6_Y
        if not math.isfinite(item.z):
            return mavlink2.MAV_MISSION_INVALID_PARAM7
    for value in (item.param1, item.param2, item.param3, item.param4):
        if math.isinf(value):
            return mavlink2.MAV_MISSION_INVALID
    return mavlink2.MAV_MISSION_ACCEPTED


def float32_decimal(value: float) -> float:
    """The shortest decimal that a float32 field value came from (20.123, not 20.1229991...)."""
    return float(str(np.float32(value)))
