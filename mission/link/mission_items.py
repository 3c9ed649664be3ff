"""Mission items as MAVLink carries them, shared by the vehicle and the ground station."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

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


INT32_MAX = 2**31 - 1
# the fields every form of an item carries alike (x and y differ: see position_scale), in
# MISSION_ITEM(_INT)'s order, with the type each holds
COMMON_FIELDS = (
    ("seq", int),
    ("frame", int),
    ("command", int),
    ("current", int),
    ("autocontinue", int),
    ("param1", float),
    ("param2", float),
    ("param3", float),
    ("param4", float),
    ("z", float),
)


def position_scale(frame: int) -> float:
    """What MISSION_ITEM_INT's x and y hold in ``frame``: 1e-7 degrees in a global frame,
    the float form's value as it is in any other (a command's params 5 and 6). The one rule
    for the float MISSION_ITEM and for waypoint files alike."""
    return 1e7 if frame in GLOBAL_FRAMES else 1.0


def to_int_field(value: float, frame: int) -> int:
    """x or y as MISSION_ITEM_INT holds it; a value it cannot hold becomes INT32_MAX (which
    validation rejects)."""
    scaled = value * position_scale(frame) if math.isfinite(value) else math.inf
    return round(scaled) if abs(scaled) < INT32_MAX else INT32_MAX


def from_int_field(value: int, frame: int) -> float:
    """x or y as the float forms (MISSION_ITEM, a waypoint file) hold it."""
    return value / position_scale(frame)


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
        """From MISSION_ITEM_INT, or from the float MISSION_ITEM (see :func:`position_scale`)."""
        common = {name: kind(getattr(msg, name)) for name, kind in COMMON_FIELDS}
        if msg.get_type() == "MISSION_ITEM_INT":
            return cls(**common, x=int(msg.x), y=int(msg.y))
        frame = common["frame"]
        return cls(**common, x=to_int_field(msg.x, frame), y=to_int_field(msg.y, frame))

    def to_int_message(self, target: tuple[int, int]) -> Any:
        """As MISSION_ITEM_INT addressed to ``target`` (system, component)."""
        fields = self._message_fields(self.x, self.y)
        return mavlink2.MAVLink_mission_item_int_message(*target, *fields, MISSION)

    def to_float_message(self, target: tuple[int, int]) -> Any:
        """As the legacy float MISSION_ITEM."""
        x, y = from_int_field(self.x, self.frame), from_int_field(self.y, self.frame)
        return mavlink2.MAVLink_mission_item_message(*target, *self._message_fields(x, y), MISSION)

    def _message_fields(self, x: float, y: float) -> tuple:
        """The fields of MISSION_ITEM(_INT) after the target, before the mission type."""
        common = [getattr(self, name) for name, _ in COMMON_FIELDS]
        return (*common[:-1], x, y, common[-1])  # z after x and y


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
