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
    """p_n, r_n and their covariances, evaluated at the measured values (MODEL.md 3.2.1)."""
    fix = gnss_fix(gps, frame)
    sigma_gnss = None
    if fix is not None:
        has_fix, sigma = world.gnss.sigma_gnss(fix[None])
        if has_fix[0]:
            sigma_gnss = sigma[0]
        else:  # the model sees no fix where the receiver has one: trust its reported accuracy
            h, v = max(gps.h_acc, 1) / 1000.0, max(gps.v_acc, 1) / 1000.0
            sigma_gnss = np.diag([h * h / 2, h * h / 2, v * v])
    relative = relative_observation(target)
    sigma_relative = world.camera.covariance(relative) if relative is not None else None
    if fix is None:
        sigma_gnss = None
    return SupportMeasurement(name, fix, sigma_gnss, relative, sigma_relative)
