"""Whether a flying quadrotor's body touched the structure or the ground, from its truth and
attitude in the tlog: its rotor rims and frame (:class:`~mission.world.contact_body.ContactBody`,
what the vehicle itself checks) along each straight segment between two truth samples, at
the attitude of the segment's start, sampled every :data:`SPACING_M`. A vehicle's own check
follows its substeps; this one, its step ends: a touch within one step and away again may be
missed here and not there (the contacts the vehicles report are counted apart).
"""

from __future__ import annotations

import numpy as np

from mission.world.contact_body import ContactBody
from mission.world.proximity import StructureProximity, segment_points

SPACING_M = 0.05


def body_touches(
    proximity: StructureProximity,
    body: ContactBody,
    samples: tuple[np.ndarray, np.ndarray, np.ndarray],
) -> bool:
    """Whether the body at ``samples`` (times (n,), centres (n, 3) with NaN where unknown,
    attitudes (n, 3, 3)) comes within a point's tolerance of the structure or the ground."""
    times, centres, attitudes = samples
    known = ~np.isnan(centres).any(axis=1)
    reach = body.reach_m
    near = proximity.clearance(np.where(known[:, None], centres, 0.0))
    for i in range(len(times) - 1):
        if not (known[i] and known[i + 1]):
            continue
        length = float(np.linalg.norm(centres[i + 1] - centres[i]))
        if near[i] > reach + length:
            continue  # no point of the body gets near anything on this segment
        points = segment_points(centres[i], centres[i + 1], SPACING_M)
        rotations = np.repeat(attitudes[i][None], len(points), axis=0)
        placed = body.rotated(points, rotations).reshape(-1, 3)
        gaps = proximity.clearance(placed) - np.tile(body.radii, len(points))
        if (gaps < 0).any():
            return True
    return False


def attitudes_at(
    attitudes: dict[tuple[int, float], np.ndarray], system: int, times: np.ndarray
) -> np.ndarray:
    """(n, 3, 3): ``system``'s attitude at each of ``times``, its latest sample's at or
    before it (level before the first)."""
    own = sorted(t for s, t in attitudes if s == system)
    if not own:
        return np.repeat(np.eye(3)[None], len(times), axis=0)
    stack = np.array([attitudes[(system, t)] for t in own])
    index = np.clip(np.searchsorted(np.array(own), times, side="right") - 1, 0, len(own) - 1)
    return stack[index]
