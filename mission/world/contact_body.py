"""What of a flying quadrotor can strike the structure or the ground: its rotor discs and the
frame between them (docs/model.md, "Contact").

A quadrotor is flat: its rotors' tips reach ``rotor_tips_m`` sideways, but above and below
the rotors' plane there is little. So against the structure and the ground its body is a set
of points in the body frame, each with a tolerance: each rotor's rim, :data:`RIM_POINTS`
points on a circle of the rotor's radius about its hub, each within half their spacing (so
the rim between two points is covered), and the frame's core, a sphere of half the lever
about the centre of mass (the centre plate, the battery, the camera). Between vehicles the
bounding sphere of ``vehicle.radius_m`` is used.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mission.config.multicopter_settings import MulticopterSettings
from mission.world.frames import quaternion_matrix

RIM_POINTS = 12


@dataclass(frozen=True)
class ContactBody:
    """Points in the body frame (FLU, m) and how close a surface may come to each."""

    points: np.ndarray  # (k, 3)
    radii: np.ndarray  # (k,)

    @classmethod
    def of(cls, body: MulticopterSettings) -> ContactBody:
        """A quadrotor's rotor rims and frame core."""
        angles = np.linspace(0.0, 2 * math.pi, RIM_POINTS, endpoint=False)
        ring = body.rotor_radius_m * np.column_stack(
            [np.cos(angles), np.sin(angles), np.zeros(RIM_POINTS)]
        )
        rims = np.vstack([hub + ring for hub in body.rotor_hubs()])
        tolerance = body.rotor_radius_m * math.sin(math.pi / RIM_POINTS)  # half the spacing
        points = np.vstack([np.zeros((1, 3)), rims])
        radii = np.concatenate([[body.lever_m / 2], np.full(len(rims), tolerance)])
        return cls(points, radii)

    @property
    def reach_m(self) -> float:
        """How far any of it reaches from the centre of mass, tolerance included."""
        return float(np.max(np.linalg.norm(self.points, axis=1) + self.radii))

    def placed(self, poses: np.ndarray) -> np.ndarray:
        """(n, k, 3): the points at each of ``poses`` ((n, 7): position, attitude quaternion
        body FLU to world ENU)."""
        rotations = [quaternion_matrix(pose[3:7]) for pose in np.atleast_2d(poses)]
        return self.rotated(np.atleast_2d(poses)[:, :3], np.array(rotations))

    def rotated(self, centres: np.ndarray, rotations: np.ndarray) -> np.ndarray:
        """(n, k, 3): the points about each of ``centres`` (n, 3) turned by ``rotations``
        (n, 3, 3: body FLU to world ENU)."""
        return centres[:, None, :] + np.einsum("nij,kj->nki", rotations, self.points)
