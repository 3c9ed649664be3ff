"""How long the work UAV's own GNSS fix is expected to stay trustworthy along its path ahead:
what the task allocation (:mod:`ground_station.roles.allocation`) releases and recalls the
supports by.

The path ahead is the work UAV's estimate, then its remaining waypoints in order, flown at its
speed limit (waiting for a margin only lengthens the time, so the figure is never late). It is
sampled every half voxel; each sample is trustworthy where the map G expects at most
``roles.own_fix_max_sigma_m``. G starts as the sky's prediction sigma_0, which is the no-fix
cap where the structure hides too many satellites, and learns (AC) where the supports met
multipath: one look-up covers the shadow and the map tests of
:mod:`ground_station.roles.own_fix` (the fix's agreement with the supports cannot be known
ahead).
"""

from __future__ import annotations

import math

import numpy as np

from ground_station.estimation.gnss_map import LocalizabilityMap


def path_ahead(xhat: np.ndarray, k: int, waypoints: np.ndarray, spacing_m: float, length_m: float):
    """Points every ``spacing_m`` along xhat -> w_k -> ... -> the last waypoint, up to
    ``length_m`` of path, and whether the path ends within that length."""
    corners = np.vstack([np.asarray(xhat, dtype=float)[None], waypoints[k:]])
    total = float(np.sum(np.linalg.norm(np.diff(corners, axis=0), axis=1)))
    arcs = np.arange(0.0, min(total, length_m) + 1e-9, spacing_m)
    if total <= length_m and (len(arcs) == 0 or arcs[-1] < total):
        arcs = np.append(arcs, total)
    return points_along(corners, arcs), total <= length_m


def points_along(corners: np.ndarray, arcs: np.ndarray) -> np.ndarray:
    """The points at the distances ``arcs`` along the polyline through ``corners`` (held at
    its end beyond it)."""
    legs = np.linalg.norm(np.diff(corners, axis=0), axis=1)
    ends = np.concatenate([[0.0], np.cumsum(legs)])
    return np.column_stack([np.interp(arcs, ends, corners[:, axis]) for axis in range(3)])


def clear_ahead_s(
    xhat: np.ndarray,
    k: int,
    waypoints: np.ndarray,
    g: LocalizabilityMap,
    max_sigma_m: float,
    speed_m_s: float,
    horizon_s: float,
) -> float:
    """Seconds of flight before the work UAV's own fix is expected untrustworthy: 0 if it is
    now, ``horizon_s`` if it stays trustworthy at least that long, infinity if it does to the
    end of the path."""
    spacing = g.grid.voxel_m / 2
    points, ends = path_ahead(xhat, k, waypoints, spacing, speed_m_s * horizon_s)
    bad = np.flatnonzero(g.smoothed(points) > max_sigma_m)
    if len(bad):
        return float(bad[0] * spacing / speed_m_s)
    return math.inf if ends else horizon_s
