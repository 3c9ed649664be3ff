"""Typed measurements from MAVLink: GPS_RAW_INT -> p_n, LANDING_TARGET -> r_n (ENU).

Only these two messages feed the estimator. SIM_STATE (truth) is logged, never read here.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ground_station.fusion import SupportMeasurement
from mission.frames import GeodeticFrame, ned_to_enu
from mission.world import World

MIN_3D_FIX = 3


def gnss_fix(message: Any | None, frame: GeodeticFrame) -> np.ndarray | None:
    """p_n in ENU from GPS_RAW_INT, or None without a 3-D fix."""
    if message is None or message.fix_type < MIN_3D_FIX:
        return None
    p = frame.to_enu(message.lat / 1e7, message.lon / 1e7, message.alt / 1000.0)
    return p if np.all(np.isfinite(p)) else None


def relative_observation(message: Any | None) -> np.ndarray | None:
    """r_n in ENU from LANDING_TARGET (NED, relative to the observer), or None if not valid."""
    if message is None or not message.position_valid:
        return None
    r = ned_to_enu(np.array([message.x, message.y, message.z], dtype=float))
    return r if np.all(np.isfinite(r)) and np.linalg.norm(r) > 0 else None


def support_measurement(
    name: str, gps: Any | None, target: Any | None, world: World, frame: GeodeticFrame
) -> SupportMeasurement:
    """p_n, r_n and their covariances from the step's GPS_RAW_INT and LANDING_TARGET."""
    fix = gnss_fix(gps, frame)
    reported = None
    if fix is not None:
        h, v = max(gps.h_acc, 1) / 1000.0, max(gps.v_acc, 1) / 1000.0
        reported = np.diag([h * h / 2, h * h / 2, v * v])
    return measurement_from_values(name, fix, relative_observation(target), world, reported)


def measurement_from_values(
    name: str,
    fix: np.ndarray | None,
    relative: np.ndarray | None,
    world: World,
    reported: np.ndarray | None = None,
) -> SupportMeasurement:
    """Covariances evaluated at the measured values (MODEL.md 3.2.1).

    Where the model sees no fix at p_n but the receiver has one, the receiver's reported
    accuracy stands in for Sigma_GNSS.
    """
    sigma_gnss = None
    if fix is not None:
        has_fix, sigma = world.gnss.sigma_gnss(fix[None])
        sigma_gnss = sigma[0] if has_fix[0] else reported
        if sigma_gnss is None:
            fix = None
    sigma_relative = world.camera.covariance(relative) if relative is not None else None
    return SupportMeasurement(name, fix, sigma_gnss, relative, sigma_relative)
