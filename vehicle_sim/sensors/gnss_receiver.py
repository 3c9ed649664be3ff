"""A vehicle's GNSS receiver: the world's fix under the receiver's live parameters, then its
failures.

In order: the fix at the truth with the world's multipath (the zones' bias, the structure's
reflections, or both) times ``SIM_MP_SCALE`` and noise of ``SIM_GPS_UERE`` (the accuracy
fields say the same sigma); the glitch ``SIM_GPS1_GLTCH_X/Y/Z`` added (degrees of latitude
and longitude and metres of altitude, as ArduPilot's SITL adds its glitch); the fix of
``SIM_GPS1_LAG_MS`` earlier (whole samples), stamped now, as a receiver that does not know
its latency sends it (the failure DELAYED, by contrast, keeps the old stamp); then an
injected failure (:mod:`~vehicle_sim.sensors.failures`). At the defaults (scale 1, no glitch, no
lag) the fix is the world's, draw for draw.
"""

from __future__ import annotations

import copy
from collections import deque
from typing import Any

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.world.frames import GeodeticFrame
from mission.world.model import World
from vehicle_sim.mavlink import telemetry
from vehicle_sim.mavlink.parameters import ParameterTable
from vehicle_sim.sensors.failures import SensorFailures, restamped

MAX_LAG_S = 1.0


class GnssReceiver:
    """Builds GPS_RAW_INT for a vehicle's true position."""

    def __init__(
        self,
        world: World,
        frame: GeodeticFrame,
        rng: np.random.Generator,
        parameters: ParameterTable,
        failures: SensorFailures,
    ) -> None:
        self._world = world
        self._frame = frame
        self._rng = rng
        self._parameters = parameters
        self._failures = failures
        self._recent: deque[Any] = deque()  # the fixes of the last MAX_LAG_S, oldest first

    def reading(self, truth: np.ndarray, time_usec: int) -> Any | None:
        """GPS_RAW_INT at ``truth`` for ``time_usec`` (None: the receiver publishes nothing)."""
        value = self._parameters.value
        sigma = value("SIM_GPS_UERE")
        fix = self._world.gnss_fix(truth, self._rng, sigma, value("SIM_MP_SCALE"))
        message = _glitched(
            telemetry.gps_raw_int(fix, self._frame, time_usec, sigma),
            value("SIM_GPS1_GLTCH_X"),
            value("SIM_GPS1_GLTCH_Y"),
            value("SIM_GPS1_GLTCH_Z"),
        )
        message = self._lagged(message, time_usec, value("SIM_GPS1_LAG_MS"))
        return self._failures.filter(mavlink2.MAVLINK_MSG_ID_GPS_RAW_INT, message)

    def _lagged(self, message: Any, time_usec: int, lag_ms: float) -> Any:
        """The newest fix at least ``lag_ms`` old (the oldest kept, if none is)."""
        recent = self._recent
        recent.append(message)
        while recent and recent[0].time_usec < time_usec - MAX_LAG_S * 1e6 - 1000:
            recent.popleft()
        if lag_ms <= 0:
            return message
        due = time_usec - lag_ms * 1000 + 1000  # a millisecond's grace for rounding
        chosen = recent[0]
        for earlier in recent:
            if earlier.time_usec > due:
                break
            chosen = earlier
        return message if chosen is message else restamped(chosen, message.time_usec)


def _glitched(message: Any, lat_deg: float, lon_deg: float, alt_m: float) -> Any:
    """``message`` moved by the glitch (a fixless message is left as it is)."""
    if (lat_deg == 0 and lon_deg == 0 and alt_m == 0) or message.fix_type < 2:
        return message
    moved = copy.copy(message)
    moved.lat = _int32(message.lat + round(lat_deg * 1e7))
    moved.lon = _int32(message.lon + round(lon_deg * 1e7))
    moved.alt = _int32(message.alt + round(alt_m * 1000))
    return moved


def _int32(value: int) -> int:
    """``value`` kept in the int32 field's range (a glitch must not make a packet unpackable)."""
    return max(-(2**31), min(2**31 - 1, value))
