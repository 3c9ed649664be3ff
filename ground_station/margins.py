"""The safety margins of a support's MPC as linear constraints: every predicted step at least
``control.min_separation_m`` from each other UAV's predicted position at that step, and at
least ``control.clearance_m`` from the structure and the ground, each widened by
``control.estimate_allowance_m`` per estimate involved (two between UAVs, one for clearance),
so that the margins hold for the true positions and not only for the estimates.

Both are linearised at the solve's guess (the previous plan, shifted) as separating
half-spaces (:mod:`mission.world.proximity`): from another UAV at o, n.v >= n.o + d with n the
unit vector from o to the guess; from each of the nearest structure pieces, n.v >= n.c + m with
c its point closest to the guess; from the ground, z >= m. A half-space lies wholly outside the
ball or the convex piece it keeps away from, so a step that satisfies it keeps the margin
exactly, however far the solve moves from the guess: conservative, never optimistic.

The other UAVs' predicted positions are the work UAV's predicted path (given: the supports give
way) and each other support's last plan shifted by a step (each support gives way to the
others' plans as they stood).
"""

from __future__ import annotations

import numpy as np

from mission.config.settings import ControlSettings
from mission.world.proximity import StructureProximity
from mission.world.structure import Structure

STRUCTURE_SLOTS = 3  # the nearest structure pieces each step considers
SLOTS = 3  # half-spaces a step keeps: the nearest to binding at the guess (fewer rows, faster)
UP = np.array([0.0, 0.0, 1.0])


class Margins:
    """The half-spaces of one support MPC's steps, with a fixed number of slots per step."""

    def __init__(self, control: ControlSettings, structure: Structure, others: int) -> None:
        allowance = control.estimate_allowance_m  # the plans are made on estimates
        self.separation = control.min_separation_m
        self.clearance = control.clearance_m
        if self.separation > 0:
            self.separation += 2 * allowance
        if self.clearance > 0:
            self.clearance += allowance
        self.proximity = StructureProximity(structure)
        self.other_slots = others if self.separation > 0 else 0
        self.structure_slots = (
            min(self.proximity.pieces, STRUCTURE_SLOTS) if self.clearance > 0 else 0
        )
        ground = 1 if self.clearance > 0 else 0
        self.candidates = self.other_slots + self.structure_slots + ground
        self.slots = min(self.candidates, SLOTS)
        self._reach_m = self.clearance + (control.horizon_steps + 1) * control.d_max_support_m

    def parameters(self, guess: np.ndarray, yhat: np.ndarray, others: np.ndarray) -> np.ndarray:
        """The NLP's margin parameters for a guess (U, 3): every step's normals (column by
        column of the (3, U slots) matrix), then their offsets. ``others`` (m, U, 3): the other
        UAVs' predicted positions; missing ones leave their slots unused (n = 0, b = -1)."""
        if self.slots == 0:
            return np.zeros(0)
        horizon = len(guess)
        normals = np.zeros((horizon, self.candidates, 3))
        offsets = np.full((horizon, self.candidates), -1.0)
        if self.other_slots:
            for j, path in enumerate(np.asarray(others, dtype=float)[: self.other_slots]):
                normals[:, j], offsets[:, j] = self._apart(guess, yhat, path)
        if self.clearance > 0:
            first = self.other_slots
            spaces = self.proximity.half_spaces(
                guess, self.structure_slots, self.clearance, self._reach_m
            )
            normals[:, first : first + self.structure_slots] = spaces.normals
            offsets[:, first : first + self.structure_slots] = spaces.offsets
            normals[:, -1], offsets[:, -1] = UP, self.clearance
        # Each step keeps the half-spaces nearest to binding at the guess (least n.g - b;
        # unused ones are never binding)
        gap = np.where(
            np.any(normals != 0, axis=2), np.einsum("usk,uk->us", normals, guess) - offsets, np.inf
        )
        keep = np.argsort(gap, axis=1, kind="stable")[:, : self.slots]
        normals = np.take_along_axis(normals, keep[..., None], axis=1)
        offsets = np.take_along_axis(offsets, keep, axis=1)
        return np.concatenate([normals.reshape(-1), offsets.reshape(-1)])

    def _apart(
        self, guess: np.ndarray, yhat: np.ndarray, other: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Per step, the half-space at ``separation`` beyond ``other`` facing the guess (from
        yhat where the guess sits on it; straight up where both do)."""
        away = guess - other
        length = np.linalg.norm(away, axis=1)
        flat = length < 1e-9
        if flat.any():
            away[flat] = yhat - other[flat]
            length[flat] = np.linalg.norm(away[flat], axis=1)
            still = length < 1e-9
            away[still], length[still] = UP, 1.0
        normals = away / length[:, None]
        return normals, np.einsum("ij,ij->i", normals, other) + self.separation

    def slack_guess(self, guess: np.ndarray, parameters: np.ndarray) -> np.ndarray:
        """Each step's largest violation at the guess (the slacks' starting point)."""
        horizon = len(guess)
        count = horizon * self.slots
        normals = parameters[: 3 * count].reshape(horizon, self.slots, 3)
        offsets = parameters[3 * count :].reshape(horizon, self.slots)
        violation = offsets - np.einsum("usk,uk->us", normals, guess)
        return np.maximum(violation.max(axis=1), 0.0)
