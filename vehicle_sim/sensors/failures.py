"""Failures injected into a vehicle's sensors (MAV_CMD_INJECT_FAILURE), as PX4's failure
injection offers them, gated by the ``SIM_FAIL_ENABLE`` parameter as PX4 gates it with
``SYS_FAILURE_EN``.

Units: the GNSS receiver (FAILURE_UNIT_SENSOR_GPS: OFF, STUCK, GARBAGE, WRONG, DELAYED) and
the camera's relative observation of the work UAV (FAILURE_UNIT_SENSOR_VIO, the vision
sensor: OFF, STUCK, WRONG); FAILURE_TYPE_OK clears a unit's failure. A failure changes only
what the vehicle publishes: the sensor is still sampled every time, so its noise draws, and
everything after the failure ends, are those of a run without it.

- OFF: nothing published.
- STUCK: the last reading before the failure, again and again (stamped with the time now).
- GARBAGE (GNSS): a random position anywhere on Earth, from the failure's own generator.
- WRONG: GNSS 10 m north of the truth's fix; camera, the work UAV seen 0.1 rad off in
  azimuth (the relative vector turned about the vertical).
- DELAYED (GNSS): the fix of one second earlier, with its own time stamp.
"""

from __future__ import annotations

import copy
import math
from collections import deque
from typing import Any

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

GPS = mavlink2.FAILURE_UNIT_SENSOR_GPS
CAMERA = mavlink2.FAILURE_UNIT_SENSOR_VIO
OK = mavlink2.FAILURE_TYPE_OK
OFF = mavlink2.FAILURE_TYPE_OFF
STUCK = mavlink2.FAILURE_TYPE_STUCK
GARBAGE = mavlink2.FAILURE_TYPE_GARBAGE
WRONG = mavlink2.FAILURE_TYPE_WRONG
DELAYED = mavlink2.FAILURE_TYPE_DELAYED
SUPPORTED = {GPS: {OK, OFF, STUCK, GARBAGE, WRONG, DELAYED}, CAMERA: {OK, OFF, STUCK, WRONG}}
STREAM_OF = {
    GPS: mavlink2.MAVLINK_MSG_ID_GPS_RAW_INT,
    CAMERA: mavlink2.MAVLINK_MSG_ID_LANDING_TARGET,
}
UNIT_NAMES = {GPS: "gps", CAMERA: "camera"}
KIND_NAMES = {
    OK: "ok",
    OFF: "off",
    STUCK: "stuck",
    GARBAGE: "garbage",
    WRONG: "wrong",
    DELAYED: "delayed",
}
WRONG_NORTH_M = 10.0
WRONG_ANGLE_RAD = 0.1
DELAY_S = 1.0
METRES_PER_DEGREE = 111_320.0  # of latitude


class SensorFailures:
    """Which failure each unit has, and what its stream publishes under it."""

    def __init__(self, seed: int, sensor_hz: float) -> None:
        self.active: dict[int, int] = {}
        self._rng = np.random.default_rng(seed)
        self._last: dict[int, Any] = {}  # the last reading published per stream, healthy
        self._stuck: dict[int, Any] = {}
        self._history = deque(maxlen=max(1, round(DELAY_S * sensor_hz)) + 1)

    def inject(self, unit: int, kind: int) -> bool:
        """Set ``unit``'s failure (OK clears it); False if it is not one of :data:`SUPPORTED`."""
        if kind not in SUPPORTED.get(unit, ()):
            return False
        stream = STREAM_OF[unit]
        if kind == OK:
            self.active.pop(unit, None)
        else:
            self.active[unit] = kind
            self._stuck[stream] = self._last.get(stream)
        return True

    def filter(self, message_id: int, message: Any) -> Any | None:
        """What the stream publishes instead of the healthy ``message`` (None: nothing)."""
        if message_id not in STREAM_OF.values():
            return message
        unit = GPS if message_id == STREAM_OF[GPS] else CAMERA
        if unit == GPS:
            self._history.append(message)
        kind = self.active.get(unit, OK)
        if kind == OK:
            self._last[message_id] = message
            return message
        if kind == OFF:
            return None
        if kind == STUCK:
            return restamped(self._stuck.get(message_id), message.time_usec)
        if kind == DELAYED:
            return self._history[0]
        failed = copy.copy(message)
        if kind == GARBAGE:
            failed.lat = int(self._rng.integers(-900_000_000, 900_000_001))
            failed.lon = int(self._rng.integers(-1_800_000_000, 1_800_000_001))
        elif unit == GPS:  # WRONG
            failed.lat = message.lat + round(WRONG_NORTH_M / METRES_PER_DEGREE * 1e7)
        elif message.position_valid:  # WRONG camera
            turn_cos, turn_sin = math.cos(WRONG_ANGLE_RAD), math.sin(WRONG_ANGLE_RAD)
            failed.x = message.x * turn_cos - message.y * turn_sin
            failed.y = message.x * turn_sin + message.y * turn_cos
            failed.angle_x = message.angle_x + WRONG_ANGLE_RAD
        return failed


def failure_name(unit: int, kind: int) -> str:
    """``UNIT TYPE`` as a scenario's ``faults:`` and the event STATUSTEXT spell it."""
    return f"{UNIT_NAMES.get(unit, str(unit))} {KIND_NAMES.get(kind, str(kind))}"


def parse_failure(name: str) -> tuple[int, int]:
    """(unit, type) of ``UNIT TYPE`` (KeyError: not one of ours)."""
    unit, _, kind = name.partition(" ")
    units = {v: k for k, v in UNIT_NAMES.items()}
    kinds = {v: k for k, v in KIND_NAMES.items()}
    return units[unit], kinds[kind]


def restamped(message: Any | None, time_usec: int) -> Any | None:
    """``message`` stamped ``time_usec`` (None if there was no reading to stick at)."""
    if message is None:
        return None
    stuck = copy.copy(message)
    stuck.time_usec = time_usec
    return stuck
