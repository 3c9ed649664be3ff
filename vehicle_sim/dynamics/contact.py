"""Contact detection: a vehicle's true body touching the structure, the ground or another
vehicle's body.

Each step's motion is a path: a point's straight segment, or a flying body's poses at its
substeps joined by straight legs. Against the structure and the ground the body is a sphere of
``vehicle.radius_m`` (a kinematic vehicle), or a flying quadrotor's rotor rims and frame at
its attitude (:mod:`~mission.world.contact_body`); the path is sampled every quarter
radius, or every :data:`BODY_SPACING_M` for a quadrotor's points (a body cannot pass through a
deck between samples). Against another vehicle the two straight motions of the centres over
the same interval give their exact closest approach
(:func:`~mission.world.proximity.closest_approach`), bounding spheres of ``vehicle.radius_m``.
A contact is a distance below the radius (below two radii between bodies): a near miss just
outside is none.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mission.world.contact_body import ContactBody
from mission.world.frames import enu_to_ned, ned_to_enu
from mission.world.proximity import StructureProximity, closest_approach, segment_points

CLEAR_SLACK_M = 1e-6  # rounding's share in the shortcut of a path clear of everything
STRUCTURE = "structure"
GROUND = "ground"
BODY_SPACING_M = 0.05  # a quadrotor's path sampled this often against the structure


@dataclass(frozen=True)
class Contact:
    """What a vehicle touched (``structure``, ``ground`` or another vehicle's name), when
    (simulated seconds), where (its own true position then, ENU) and the distance found
    (centre to surface; a quadrotor's point to the surface less the point's tolerance; centre
    to centre between vehicles)."""

    other: str
    time_s: float
    position_m: np.ndarray
    distance_m: float

    def text(self, crashed: bool) -> str:
        """The STATUSTEXT (at most 50 characters): what, when and where."""
        x, y, z = (float(v) for v in self.position_m)
        head = "Crash" if crashed else "Contact"
        return f"{head}: {self.other} t={self.time_s:.2f} at {x:.1f},{y:.1f},{z:.1f}"[:50]


def as_sent(position: np.ndarray) -> np.ndarray:
    """A position as the truth channel carries it (NED in float32, back in ENU): two vehicles
    judge their closest approach from the same numbers."""
    return ned_to_enu(np.asarray(enu_to_ned(position), dtype=np.float32).astype(float))


def dense_path(
    path: np.ndarray, start_s: float, end_s: float, spacing_m: float
) -> tuple[np.ndarray, np.ndarray]:
    """``path``'s points at equal times from ``start_s`` to ``end_s``, with points added along
    each leg so that none is more than ``spacing_m`` from the next, and their times."""
    legs = np.diff(path, axis=0)
    cuts = np.maximum(np.ceil(np.linalg.norm(legs, axis=1) / spacing_m), 1).astype(int)
    leg = np.repeat(np.arange(len(legs)), cuts)
    fraction = (np.arange(len(leg)) - np.repeat(np.cumsum(cuts) - cuts, cuts)) / cuts[leg]
    joints = np.linspace(start_s, end_s, len(path))
    points = np.vstack([path[leg] + fraction[:, None] * legs[leg], path[-1:]])
    times = np.append(joints[leg] + fraction * (joints[leg + 1] - joints[leg]), end_s)
    return points, times


class ContactDetector:
    """One vehicle's contact checks, with its radius and the structure's proximity."""

    def __init__(
        self, proximity: StructureProximity, radius_m: float, body: ContactBody | None = None
    ) -> None:
        """``body``: a quadrotor's points against the structure and the ground (None: the
        sphere of ``radius_m``)."""
        self.proximity = proximity
        self.radius_m = radius_m
        self.body = body

    def along(self, path: np.ndarray, start_s: float, end_s: float) -> list[Contact]:
        """The first contact with the structure and the first with the ground along ``path``
        ((n, 3) positions or (n, 7) poses at equal times from ``start_s`` to ``end_s``: a
        flying body's substeps, or a point's two ends)."""
        path = np.asarray(path, dtype=float)
        centres = path[:, :3]
        # no point of the body is further from the path's start than this: where the start is
        # more than this from the structure and the ground, nothing touches them (a distance
        # changes no faster than the point moves)
        reach = float(np.sqrt(np.max(np.sum((centres - centres[0]) ** 2, axis=1))))
        size = self.radius_m if self.body is None else self.body.reach_m
        clear = size + reach + CLEAR_SLACK_M
        if centres[0, 2] > clear and self.proximity.distance(centres[:1])[0] > clear:
            return []
        if self.body is None or path.shape[1] < 7:
            return self._sphere_along(centres, start_s, end_s)
        return self._body_along(path, start_s, end_s)

    def _sphere_along(self, path: np.ndarray, start_s: float, end_s: float) -> list[Contact]:
        if len(path) == 2:
            points = segment_points(path[0], path[1], self.radius_m / 4)
            times = np.linspace(start_s, end_s, len(points))
        else:
            points, times = dense_path(path, start_s, end_s, self.radius_m / 4)
        gaps = (self.proximity.distance(points), points[:, 2])
        return _first_contacts(gaps, self.radius_m, points, times)

    def _body_along(self, poses: np.ndarray, start_s: float, end_s: float) -> list[Contact]:
        """A quadrotor's points along its poses (each leg's attitude its start's)."""
        centres, times = dense_path(poses[:, :3], start_s, end_s, BODY_SPACING_M)
        joints = np.linspace(start_s, end_s, len(poses))
        legs = np.clip(np.searchsorted(joints, times, side="right") - 1, 0, len(poses) - 1)
        placed = self.body.placed(np.column_stack([centres, poses[legs, 3:7]]))
        count, k = placed.shape[:2]
        flat = placed.reshape(count * k, 3)
        slack = np.tile(self.body.radii, count)
        gaps = (self.proximity.distance(flat) - slack, flat[:, 2] - slack)
        return _first_contacts(gaps, 0.0, np.repeat(centres, k, axis=0), np.repeat(times, k))

    def with_vehicles(
        self,
        own: tuple[np.ndarray, np.ndarray],
        others: dict[str, tuple[np.ndarray, np.ndarray]],
        start_s: float,
        end_s: float,
    ) -> list[Contact]:
        """Contacts with other vehicles over a step: ``own`` and each of ``others`` are
        (position at start, position at end) as the truth channel carries them."""
        found = []
        for name, (start, end) in sorted(others.items()):
            distance, fraction = closest_approach(own[0], own[1], start, end)
            if distance < 2 * self.radius_m:
                where = own[0] + fraction * (own[1] - own[0])
                when = start_s + fraction * (end_s - start_s)
                found.append(Contact(name, when, where, distance))
        return found


def _first_contacts(
    gaps: tuple[np.ndarray, np.ndarray], radius_m: float, where: np.ndarray, times: np.ndarray
) -> list[Contact]:
    """The first sample closer than ``radius_m`` to the structure (``gaps[0]``) and the first
    to the ground (``gaps[1]``), as contacts at the centre ``where`` was then."""
    found = []
    for other, gap in zip((STRUCTURE, GROUND), gaps):
        touching = np.flatnonzero(gap < radius_m)
        if len(touching):
            i = int(touching[0])
            found.append(Contact(other, float(times[i]), where[i], float(gap[i])))
    return found


class ContactWatch:
    """A vehicle's contacts over a run: each new contact (one per episode of touching the same
    thing) is kept, and the first one is a crash when the run stops on crashes."""

    def __init__(self, detector: ContactDetector, stop_on_crash: bool) -> None:
        self.detector = detector
        self.stop_on_crash = stop_on_crash
        self.contacts: list[Contact] = []
        self.crash: Contact | None = None
        self._touching: dict[str, set[str]] = {"vehicles": set(), "surroundings": set()}

    def new_contacts(self, kind: str, found: list[Contact]) -> list[Contact]:
        """The contacts of ``found`` (a check of ``kind``: vehicles or surroundings) that
        begin an episode; the first of them becomes the crash if there is to be one."""
        fresh = [c for c in found if c.other not in self._touching[kind]]
        self._touching[kind] = {c.other for c in found}
        self.contacts += fresh
        if fresh and self.stop_on_crash and self.crash is None:
            self.crash = fresh[0]
        return fresh
