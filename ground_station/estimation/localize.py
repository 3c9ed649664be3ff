"""Step 1 of the control cycle, localize: each support's GNSS fix p_n and camera observation
r_n (ENU), with the covariances the ground station can predict for them.

What a support reports arrives as MAVLink (GPS_RAW_INT -> p_n, LANDING_TARGET -> r_n; see
:func:`reports_from_messages`). Only these two messages feed the estimator; SIM_STATE (the
truth) is logged, never read.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any, Protocol

import numpy as np

from ground_station.estimation.fusion import SupportMeasurement
from mission.world.frames import GeodeticFrame, ned_to_enu
from mission.world.model import KnownWorld

MIN_3D_FIX = 3
IMPLAUSIBLE_FIX_M = 100.0  # a fix this far outside the workspace is a failed receiver's


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


@dataclass(frozen=True)
class SupportReport:
    """What one support reported this cycle: p_n and r_n (ENU; None where missing), the
    receiver's own accuracy as a covariance, and how old each measurement is at the cycle's
    time (simulated seconds; zero in lockstep)."""

    name: str
    fix: np.ndarray | None
    relative: np.ndarray | None
    reported: np.ndarray | None = None
    fix_age_s: float = 0.0
    relative_age_s: float = 0.0
    belief: np.ndarray | None = None  # where its autopilot believes it is (ENU), this step


class Sample(Protocol):
    """A support's messages for a cycle
    (:class:`ground_station.links.vehicle_links.SupportSample`)."""

    name: str
    gps: Any | None
    target: Any | None
    gps_age_s: float
    target_age_s: float
    belief: Any | None


def reports_from_messages(samples: Sequence[Sample], frame: GeodeticFrame) -> list[SupportReport]:
    """Each support's report from its GPS_RAW_INT and LANDING_TARGET for the cycle."""
    reports = []
    for sample in samples:
        gps = sample.gps
        fix = gnss_fix(gps, frame)
        reported = None
        if fix is not None:
            h, v = max(gps.h_acc, 1) / 1000.0, max(gps.v_acc, 1) / 1000.0
            reported = np.diag([h * h / 2, h * h / 2, v * v])
        relative = relative_observation(sample.target)
        reports.append(
            SupportReport(
                sample.name,
                fix,
                relative,
                reported,
                sample.gps_age_s if fix is not None else 0.0,
                sample.target_age_s if relative is not None else 0.0,
                _belief(sample.belief),
            )
        )
    return reports


def _belief(message: Any | None) -> np.ndarray | None:
    """LOCAL_POSITION_NED as ENU (None where missing or not finite)."""
    if message is None:
        return None
    belief = ned_to_enu(np.array([message.x, message.y, message.z], dtype=float))
    return belief if np.all(np.isfinite(belief)) else None


def plausible_fix(fix: np.ndarray | None, world: KnownWorld) -> bool:
    """False for a fix more than :data:`IMPLAUSIBLE_FIX_M` outside the workspace."""
    if fix is None:
        return True
    low = np.array(world.workspace.min_m) - IMPLAUSIBLE_FIX_M
    high = np.array(world.workspace.max_m) + IMPLAUSIBLE_FIX_M
    return bool(np.all((fix >= low) & (fix <= high)))


def localize(values: Sequence[SupportReport], world: KnownWorld) -> list[SupportMeasurement]:
    """p_n and r_n with covariances evaluated at the measured values (docs/model.md, "Selective
    fusion (3.2.1) and feedback (3.2.2)"): the GNSS geometry of every fix in one batch and the
    camera's Sigma_r of every observation in another (the same numbers as one at a time,
    tested).

    Where the model sees no fix at p_n but the receiver has one, the receiver's reported
    accuracy stands in for Sigma_GNSS. A fix more than :data:`IMPLAUSIBLE_FIX_M` outside the
    workspace is no fix (a receiver sending garbage): that support is then handled as one
    without GNSS.
    """
    values = [v if plausible_fix(v.fix, world) else replace(v, fix=None) for v in values]
    with_fix = [v for v in values if v.fix is not None]
    sigma_of: dict[str, np.ndarray | None] = {}
    if with_fix:
        has_fix, sigma = world.gnss.sigma_gnss(np.array([v.fix for v in with_fix]))
        for i, v in enumerate(with_fix):
            sigma_of[v.name] = sigma[i] if has_fix[i] else v.reported
    observed = [v for v in values if v.relative is not None]
    sigma_relative_of: dict[str, np.ndarray] = {}
    if observed:
        covariances = world.camera.covariance(np.array([v.relative for v in observed]))
        sigma_relative_of = {v.name: covariances[i] for i, v in enumerate(observed)}
    measurements = []
    for v in values:
        sigma_gnss = sigma_of.get(v.name)
        fix = v.fix if sigma_gnss is not None else None
        measurements.append(
            SupportMeasurement(
                v.name,
                fix,
                sigma_gnss,
                v.relative,
                sigma_relative_of.get(v.name),
                v.reported,
                v.belief,
            )
        )
    return measurements
