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

SLOTS = 3  # half-spaces a step keeps, the nearest to binding at the guess (fewer rows)
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
        # every structure piece and the ground are candidates; a step keeps the SLOTS nearest
        pieces = self.proximity.pieces + 1 if self.clearance > 0 else 0
        self.slots = min(self.other_slots + pieces, SLOTS)
        self._reach_m = self.clearance + (control.horizon_steps + 1) * control.d_max_support_m

    def parameters(self, guess: np.ndarray, yhat: np.ndarray, others: np.ndarray) -> np.ndarray:
        """The NLP's margin parameters for a guess (U, 3): every step's normals (column by
        column of the (3, U slots) matrix), then their offsets. ``others`` (m, U, 3): the other
        UAVs' predicted positions. Each step keeps the ``slots`` half-spaces nearest to
        binding at the guess (least n.g - b); a slot left over is unused (n = 0, b = -1)."""
        if self.slots == 0:
            return np.zeros(0)
        horizon = len(guess)
        normals, offsets = [], []
        others = np.asarray(others, dtype=float)[: self.other_slots]
        if len(others):
            n, b = self._apart(guess, yhat, others)
            normals.append(n)
            offsets.append(b)
        if self.clearance > 0:
            if self.proximity.pieces:
                distance, closest, n = self.proximity.closest(guess)
                far = distance > self._reach_m
                n[far] = 0.0
                b = np.einsum("usk,usk->us", n, closest) + self.clearance
                b[far] = -1.0
                normals.append(n)
                offsets.append(b)
            normals.append(np.broadcast_to(UP, (horizon, 1, 3)))
            offsets.append(np.full((horizon, 1), self.clearance))
        normals, offsets = np.concatenate(normals, axis=1), np.concatenate(offsets, axis=1)
        if normals.shape[1] > self.slots:
            gap = np.einsum("usk,uk->us", normals, guess) - offsets
            keep = np.argsort(gap, axis=1, kind="stable")[:, : self.slots]
            rows = np.arange(horizon)[:, None]
            normals, offsets = normals[rows, keep], offsets[rows, keep]
        elif normals.shape[1] < self.slots:
            missing = self.slots - normals.shape[1]
            normals = np.concatenate([normals, np.zeros((horizon, missing, 3))], axis=1)
            offsets = np.concatenate([offsets, np.full((horizon, missing), -1.0)], axis=1)
        return np.concatenate([normals.reshape(-1), offsets.reshape(-1)])

    def _apart(
        self, guess: np.ndarray, yhat: np.ndarray, others: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Per step (rows) and other UAV (columns), the half-space at ``separation`` beyond
        the other's position facing the guess (from yhat where the guess sits on it;
        straight up where both do)."""
        other = others.transpose(1, 0, 2)  # (U, m, 3)
        away = guess[:, None] - other
        length = np.sqrt(np.einsum("usk,usk->us", away, away))
        flat = length < 1e-9
        if flat.any():
            away[flat] = (yhat - other)[flat]
            length[flat] = np.linalg.norm(away[flat], axis=1)
            still = length < 1e-9
            away[still], length[still] = UP, 1.0
        normals = away / length[..., None]
        return normals, np.einsum("usk,usk->us", normals, other) + self.separation

    def slack_guess(self, guess: np.ndarray, parameters: np.ndarray) -> np.ndarray:
        """Each step's largest violation at the guess (the slacks' starting point)."""
        horizon = len(guess)
        count = horizon * self.slots
        normals = parameters[: 3 * count].reshape(horizon, self.slots, 3)
        offsets = parameters[3 * count :].reshape(horizon, self.slots)
        violation = offsets - np.einsum("usk,uk->us", normals, guess)
        return np.maximum(violation.max(axis=1), 0.0)
