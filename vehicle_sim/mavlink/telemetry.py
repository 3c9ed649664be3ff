"""Builders of the telemetry a simulated vehicle sends (pymavlink generated classes only)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.world.camera import Observation
from mission.world.frames import (
    GeodeticFrame,
    enu_to_ned,
    flu_to_frd,
    quaternion_matrix,
    swap_attitude_frames,
)
from mission.world.gnss import GnssFix
from vehicle_sim.mavlink import modes

UINT16_UNKNOWN = 65535
SOFTWARE_VERSION = (0 << 24) | (1 << 16) | (0 << 8) | 255  # 0.1.0, FIRMWARE_VERSION_TYPE_OFFICIAL
CAPABILITIES = (
    mavlink2.MAV_PROTOCOL_CAPABILITY_MISSION_INT
    | mavlink2.MAV_PROTOCOL_CAPABILITY_COMMAND_INT
    | mavlink2.MAV_PROTOCOL_CAPABILITY_SET_POSITION_TARGET_LOCAL_NED
    | mavlink2.MAV_PROTOCOL_CAPABILITY_MAVLINK2
    | mavlink2.MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_C_CAST  # see parameters.py
)


def _u16(value: float) -> int:
    return int(min(max(round(value), 0), UINT16_UNKNOWN - 1))


def _i16(value: float) -> int:
    """An int16 field's value, held at its range (327 m/s in cm/s: no flight of ours, but a
    vehicle the settings made unstable must still say where it is)."""
    return int(min(max(round(value), -(2**15)), 2**15 - 1))


def heartbeat(
    mode: int, armed: bool, failsafe: bool, crashed: bool = False
) -> mavlink2.MAVLink_heartbeat_message:
    """A quadrotor's HEARTBEAT with ArduPilot's mode numbers, armed state and health (a crashed
    vehicle reports MAV_STATE_EMERGENCY)."""
    base = mavlink2.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED | mavlink2.MAV_MODE_FLAG_STABILIZE_ENABLED
    if mode in (modes.GUIDED, modes.AUTO):
        base |= mavlink2.MAV_MODE_FLAG_GUIDED_ENABLED
    if mode == modes.AUTO:
        base |= mavlink2.MAV_MODE_FLAG_AUTO_ENABLED
    if armed:
        base |= mavlink2.MAV_MODE_FLAG_SAFETY_ARMED
    state = mavlink2.MAV_STATE_ACTIVE if armed else mavlink2.MAV_STATE_STANDBY
    if failsafe:
        state = mavlink2.MAV_STATE_CRITICAL
    if crashed:
        state = mavlink2.MAV_STATE_EMERGENCY
    return mavlink2.MAVLink_heartbeat_message(
        mavlink2.MAV_TYPE_QUADROTOR, mavlink2.MAV_AUTOPILOT_ARDUPILOTMEGA, base, mode, state, 3
    )


def sys_status(bad_packets: int) -> mavlink2.MAVLink_sys_status_message:
    """SYS_STATUS: GPS and vision position present and healthy; errors_comm counts bad packets."""
    sensors = mavlink2.MAV_SYS_STATUS_SENSOR_GPS | mavlink2.MAV_SYS_STATUS_SENSOR_VISION_POSITION
    bad = min(bad_packets, 65535)
    return mavlink2.MAVLink_sys_status_message(
        sensors, sensors, sensors, 0, 16800, -1, -1, 0, bad, 0, 0, 0, 0, 0, 0, 0
    )


_FIX_TYPE = {  # a receiver's solution as GPS_RAW_INT's fix_type
    "rtk-fixed": mavlink2.GPS_FIX_TYPE_RTK_FIXED,
    "rtk-float": mavlink2.GPS_FIX_TYPE_RTK_FLOAT,
    "code": mavlink2.GPS_FIX_TYPE_DGPS,
}


def gps_raw_int(
    fix: GnssFix, frame: GeodeticFrame, time_usec: int, sigma_uere_m: float
) -> mavlink2.MAVLink_gps_raw_int_message:
    """GPS_RAW_INT from a receiver fix: the satellites it used, its solution's fix type, and
    accuracy fields from the geometry it used (never its bias)."""
    if not fix.has_fix or fix.position_m is None:
        return mavlink2.MAVLink_gps_raw_int_message(
            time_usec,
            mavlink2.GPS_FIX_TYPE_NO_FIX,
            0,
            0,
            0,
            UINT16_UNKNOWN,
            UINT16_UNKNOWN,
            UINT16_UNKNOWN,
            UINT16_UNKNOWN,
            fix.n_visible,
            0,
            0,
            0,
            0,
            0,
            0,
        )
    lat_e7, lon_e7, alt_m = frame.to_degE7(fix.position_m)
    hdop, vdop = float(fix.hdop or 0.0), float(fix.vdop or 0.0)
    return mavlink2.MAVLink_gps_raw_int_message(
        time_usec,
        _FIX_TYPE[fix.solution],
        lat_e7,
        lon_e7,
        round(alt_m * 1000),
        _u16(hdop * 100),
        _u16(vdop * 100),
        UINT16_UNKNOWN,
        UINT16_UNKNOWN,
        fix.n_visible,
        round(alt_m * 1000),
        round(sigma_uere_m * hdop * 1000),
        round(sigma_uere_m * vdop * 1000),
        0,
        0,
        0,
    )


def landing_target(
    observation: Observation, time_usec: int, target_system: int
) -> mavlink2.MAVLink_landing_target_message:
    """LANDING_TARGET with the camera's relative vector in NED, relative to the observer."""
    if not observation.valid or observation.relative_m is None:
        return mavlink2.MAVLink_landing_target_message(
            time_usec,
            target_system,
            mavlink2.MAV_FRAME_LOCAL_OFFSET_NED,
            0,
            0,
            0,
            0,
            0,
            0,
            0,
            0,
            [1, 0, 0, 0],
            mavlink2.LANDING_TARGET_TYPE_VISION_OTHER,
            0,
        )
    north, east, down = (float(v) for v in enu_to_ned(observation.relative_m))
    distance = math.sqrt(north**2 + east**2 + down**2)
    angle_x = math.atan2(east, north)
    angle_y = math.atan2(-down, math.hypot(north, east))
    return mavlink2.MAVLink_landing_target_message(
        time_usec,
        target_system,
        mavlink2.MAV_FRAME_LOCAL_OFFSET_NED,
        angle_x,
        angle_y,
        distance,
        0,
        0,
        north,
        east,
        down,
        [1, 0, 0, 0],
        mavlink2.LANDING_TARGET_TYPE_VISION_OTHER,
        1,
    )


def local_position_ned(
    position_enu: np.ndarray, velocity_enu: np.ndarray, time_boot_ms: int
) -> mavlink2.MAVLink_local_position_ned_message:
    """LOCAL_POSITION_NED (origin: the scenario's geodetic anchor)."""
    n, e, d = (float(v) for v in enu_to_ned(position_enu))
    vn, ve, vd = (float(v) for v in enu_to_ned(velocity_enu))
    return mavlink2.MAVLink_local_position_ned_message(time_boot_ms, n, e, d, vn, ve, vd)


def global_position_int(
    position_enu: np.ndarray,
    velocity_enu: np.ndarray,
    home_enu: np.ndarray,
    frame: GeodeticFrame,
    time_boot_ms: int,
) -> mavlink2.MAVLink_global_position_int_message:
    """GLOBAL_POSITION_INT of the believed position."""
    lat_e7, lon_e7, alt_m = frame.to_degE7(position_enu)
    vn, ve, vd = (_i16(float(v) * 100) for v in enu_to_ned(velocity_enu))
    relative_mm = round((float(position_enu[2]) - float(home_enu[2])) * 1000)
    return mavlink2.MAVLink_global_position_int_message(
        time_boot_ms, lat_e7, lon_e7, round(alt_m * 1000), relative_mm, vn, ve, vd, UINT16_UNKNOWN
    )


@dataclass(frozen=True)
class Attitude:
    """An attitude as MAVLink reports it: the quaternion (w, x, y, z) of body FRD to world NED,
    roll, pitch and yaw (rad, ZYX) and the body rates (rad/s, FRD)."""

    quaternion: tuple[float, float, float, float]
    euler: tuple[float, float, float]
    rates: tuple[float, float, float]

    @classmethod
    def of(cls, quaternion_enu_flu: np.ndarray, rates_flu: np.ndarray) -> Attitude:
        """From the simulation's frames (body FLU to world ENU, rates in FLU)."""
        r = swap_attitude_frames(quaternion_matrix(quaternion_enu_flu))
        roll = math.atan2(r[2, 1], r[2, 2])
        pitch = math.asin(max(-1.0, min(1.0, -r[2, 0])))
        yaw = math.atan2(r[1, 0], r[0, 0])
        qw = math.sqrt(max(0.0, 1 + r[0, 0] + r[1, 1] + r[2, 2])) / 2
        if qw > 1e-6:
            q = (
                qw,
                (r[2, 1] - r[1, 2]) / (4 * qw),
                (r[0, 2] - r[2, 0]) / (4 * qw),
                (r[1, 0] - r[0, 1]) / (4 * qw),
            )
        else:  # a half turn: from the largest diagonal term
            i = int(np.argmax(np.diag(r)))
            j, k = (i + 1) % 3, (i + 2) % 3
            v = [0.0, 0.0, 0.0]
            v[i] = math.sqrt(max(0.0, 1 + r[i, i] - r[j, j] - r[k, k])) / 2
            v[j] = (r[j, i] + r[i, j]) / (4 * v[i])
            v[k] = (r[k, i] + r[i, k]) / (4 * v[i])
            q = ((r[k, j] - r[j, k]) / (4 * v[i]), *v)
        p, q_rate, r_rate = (float(v) for v in flu_to_frd(rates_flu))
        return cls(tuple(float(v) for v in q), (roll, pitch, yaw), (p, q_rate, r_rate))


def attitude_message(attitude: Attitude, time_boot_ms: int) -> mavlink2.MAVLink_attitude_message:
    """ATTITUDE: what MAVProxy's and QGroundControl's attitude displays read."""
    return mavlink2.MAVLink_attitude_message(time_boot_ms, *attitude.euler, *attitude.rates)


def sim_state(
    truth_enu: np.ndarray,
    velocity_enu: np.ndarray,
    frame: GeodeticFrame,
    attitude: Attitude | None = None,
) -> mavlink2.MAVLink_sim_state_message:
    """SIM_STATE with the true position (lat_int/lon_int carry centimetre resolution), velocity
    and, for a flying body, attitude and rates (a kinematic point: level, north)."""
    lat, lon, alt = frame.to_geodetic(truth_enu)
    vn, ve, vd = (float(v) for v in enu_to_ned(velocity_enu))
    q = (1.0, 0.0, 0.0, 0.0) if attitude is None else attitude.quaternion
    euler = (0.0, 0.0, 0.0) if attitude is None else attitude.euler
    rates = (0.0, 0.0, 0.0) if attitude is None else attitude.rates
    return mavlink2.MAVLink_sim_state_message(
        *q,
        *euler,
        0,
        0,
        0,
        *rates,
        lat,
        lon,
        alt,
        0,
        0,
        vn,
        ve,
        vd,
        round(lat * 1e7),
        round(lon * 1e7),
    )


def autopilot_version(system_id: int) -> mavlink2.MAVLink_autopilot_version_message:
    """AUTOPILOT_VERSION advertising what this simulator really supports."""
    return mavlink2.MAVLink_autopilot_version_message(
        CAPABILITIES,
        SOFTWARE_VERSION,
        0,
        0,
        0,
        [0] * 8,
        [0] * 8,
        [0] * 8,
        0,
        0,
        system_id,
        [0] * 18,
    )
