"""When each of a vehicle's streams is due: its interval (the scenario's rates, changed by
SET_MESSAGE_INTERVAL or a parameter) and when it was last sent, in simulated time."""

from __future__ import annotations

from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.config.planner_vehicle_settings import VehicleSettings

SENSOR_STREAMS = (
    mavlink2.MAVLINK_MSG_ID_SIM_STATE,
    mavlink2.MAVLINK_MSG_ID_LOCAL_POSITION_NED,
    mavlink2.MAVLINK_MSG_ID_GLOBAL_POSITION_INT,
    mavlink2.MAVLINK_MSG_ID_GPS_RAW_INT,
    mavlink2.MAVLINK_MSG_ID_LANDING_TARGET,
)
FLYING_STREAMS = (mavlink2.MAVLINK_MSG_ID_ATTITUDE,)  # a multicopter's, at the sensor rate
STATUS_STREAMS = (
    mavlink2.MAVLINK_MSG_ID_HEARTBEAT,
    mavlink2.MAVLINK_MSG_ID_SYS_STATUS,
    mavlink2.MAVLINK_MSG_ID_MISSION_CURRENT,
)
PUBLISHING_ORDER = (*SENSOR_STREAMS, *FLYING_STREAMS, *STATUS_STREAMS)
DUE_TOLERANCE_S = 1e-6


class StreamSchedule:
    """Each stream's interval (None: stopped) and the simulated time it was last sent."""

    def __init__(self, settings: VehicleSettings, flying: bool, camera: bool) -> None:
        """The scenario's rates; ATTITUDE only for a ``flying`` body, LANDING_TARGET only for
        a vehicle with a ``camera`` (the work UAV carries none looking at itself)."""
        self.intervals_s: dict[int, float | None] = {
            **{m: 1.0 / settings.sensor_hz for m in SENSOR_STREAMS},
            mavlink2.MAVLINK_MSG_ID_HEARTBEAT: 1.0 / settings.heartbeat_hz,
            mavlink2.MAVLINK_MSG_ID_SYS_STATUS: 1.0 / settings.status_hz,
            mavlink2.MAVLINK_MSG_ID_MISSION_CURRENT: 1.0 / settings.status_hz,
        }
        if flying:
            self.intervals_s.update({m: 1.0 / settings.sensor_hz for m in FLYING_STREAMS})
        if not camera:
            del self.intervals_s[mavlink2.MAVLINK_MSG_ID_LANDING_TARGET]
        self._defaults = dict(self.intervals_s)
        self._last_sent_s: dict[int, float] = {}

    def due(self, time_s: float) -> list[int]:
        """The streams due at ``time_s``, in the order a step publishes them."""
        return [m for m in PUBLISHING_ORDER if self.is_due(m, time_s)]

    def is_due(self, message_id: int, time_s: float) -> bool:
        """Whether the stream ``message_id`` is due at ``time_s`` (never, if stopped)."""
        interval = self.intervals_s.get(message_id)
        if interval is None:
            return False
        last = self._last_sent_s.get(message_id)
        return last is None or time_s - last >= interval - DUE_TOLERANCE_S

    def sent(self, message_id: int, time_s: float) -> None:
        """The stream's message was sent (or, its sensor failed, was due) at ``time_s``."""
        self._last_sent_s[message_id] = time_s

    def set_interval(self, message_id: int, interval_us: float) -> bool:
        """SET_MESSAGE_INTERVAL: -1 stops, 0 restores the default; False if not a stream."""
        if message_id not in self._defaults:
            return False
        if interval_us < 0:
            self.intervals_s[message_id] = None
        elif interval_us == 0:
            self.intervals_s[message_id] = self._defaults[message_id]
        else:
            self.intervals_s[message_id] = interval_us / 1e6
        return True
