"""The safety margins of a support's MPC as linear constraints: every predicted step at least
``control.min_separation_m`` from each other UAV's predicted position at that step, and at
least ``control.clearance_m`` from the structure and the ground, each widened by
``control.estimate_allowance_m`` and ``control.tracking_allowance_m`` per vehicle involved (two
between UAVs, one for clearance), so that the margins hold for the true positions and not only
for the estimates, and for a vehicle that lags its plan.

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

import math

import numpy as np

from ground_station.support_mpc import margin_spaces
from ground_station.support_mpc.margin_spaces import MARGIN_SPACES, SpaceRules, half_spaces_function
from ground_station.support_mpc.nlp_cache import compiled_keyed_function
from mission.codegen import casadi_cache
from mission.codegen.build_key import build_key
from mission.codegen.casadi_buffer import BufferedFunction
from mission.config.settings import ControlSettings
from mission.world.proximity import StructureProximity
from mission.world.structure import Structure

SLOTS = 3  # half-spaces a step keeps, the nearest to binding at the guess (fewer rows)
Space = tuple[tuple[float, float, float], float]  # n, b of the half-space n.v >= b
UNUSED: Space = ((0.0, 0.0, 0.0), -1.0)  # a slot no half-space fills
MARGIN_SPACES_BUILT_BY = (margin_spaces, casadi_cache)  # what its cache key covers (traced)


class Margins:
    """The half-spaces of one support MPC's steps, with a fixed number of slots per step."""

    def __init__(
        self, control: ControlSettings, structure: Structure, others: int, compiled: bool = True
    ) -> None:
        allowance = control.allowance_m  # the plans are made on estimates, flown with a lag
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
        self._boxes = [
            (low.tolist(), high.tolist())
            for low, high in zip(self.proximity.low, self.proximity.high, strict=True)
        ]
        self._horizon = control.horizon_steps
        self._function = self._compiled(compiled)
        self._radii: dict[tuple[int, float, bool], np.ndarray] = {}  # least_slack's, by reach

    def _compiled(self, compiled: bool) -> BufferedFunction | None:
        """The half-spaces as a casadi function (:mod:`ground_station.support_mpc.margin_spaces`),
        compiled where a C compiler is there and ``compiled`` asks for it; None where it does
        not apply (no margins, or a mesh file among the pieces)."""
        if self.slots == 0 or (self.clearance > 0 and self.proximity.has_file_mesh):
            return None
        rules, horizon = self.space_rules(), self._horizon
        key = build_key([rules, horizon], MARGIN_SPACES_BUILT_BY)
        function = compiled_keyed_function(
            MARGIN_SPACES, key, lambda: half_spaces_function(rules, horizon), compiled
        )
        return BufferedFunction(function, ("spaces", "inside"))

    def space_rules(self) -> SpaceRules:
        """What the compiled half-spaces are made of (boxes only)."""
        return SpaceRules(
            self.separation,
            self.clearance,
            self._reach_m,
            self.proximity.low,
            self.proximity.high,
            self.other_slots,
            self.slots,
        )

    def parameters(self, guess: np.ndarray, yhat: np.ndarray, others: np.ndarray) -> np.ndarray:
        """The NLP's margin parameters for a guess (U, 3): every step's normals (column by
        column of the (3, U slots) matrix), then their offsets. ``others`` (m, U, 3): the other
        UAVs' predicted positions. Each step keeps the ``slots`` half-spaces nearest to
        binding at the guess (least n.g - b; on a tie, and with no more than ``slots``, in
        the order others, structure pieces, ground); a slot left over is unused (n = 0,
        b = -1).

        Five points and a few dozen half-spaces: in plain floats this takes half the time
        numpy's per-call overhead makes it take (86 against 176 us on Along's problems)."""
        if self.slots == 0:
            return np.zeros(0)
        others = np.asarray(others, dtype=float)[: self.other_slots]
        if self._function is not None and others.shape == (self.other_slots, self._horizon, 3):
            found = self._function(guess=np.ravel(guess), yhat=yhat, others=others.ravel())
            if found["inside"][0] == 0:
                return found["spaces"]
        points = np.asarray(guess, dtype=float).tolist()
        others = others.tolist()
        pieces = self._pieces(guess) if self.clearance > 0 else [[] for _ in points]
        start = np.asarray(yhat, dtype=float).tolist()
        normals: list[float] = []
        offsets: list[float] = []
        for step, point in enumerate(points):
            spaces = [self._apart(point, start, other[step]) for other in others]
            spaces += pieces[step]
            if self.clearance > 0:
                spaces.append(((0.0, 0.0, 1.0), self.clearance))  # the ground
            if len(spaces) > self.slots:
                spaces.sort(key=lambda space: _dot(space[0], point) - space[1])  # stable
                spaces = spaces[: self.slots]
            spaces += [UNUSED] * (self.slots - len(spaces))
            for normal, offset in spaces:
                normals.extend(normal)
                offsets.append(offset)
        return np.array(normals + offsets)

    def _apart(self, point: list[float], start: list[float], other: list[float]) -> Space:
        """The half-space at ``separation`` beyond the other UAV's position facing the guess
        (from yhat where the guess sits on it; straight up where both do)."""
        away = [point[k] - other[k] for k in range(3)]
        length = math.sqrt(_dot(away, away))
        if length < 1e-9:
            away = [start[k] - other[k] for k in range(3)]
            length = math.sqrt(_dot(away, away))
            if length < 1e-9:
                away, length = [0.0, 0.0, 1.0], 1.0
        normal = (away[0] / length, away[1] / length, away[2] / length)
        return normal, _dot(normal, other) + self.separation

    def _pieces(self, guess: np.ndarray) -> list[list[Space]]:
        """Per step, each structure piece's half-space at ``clearance`` beyond its point
        closest to the guess (n = 0, b = -1 for a piece out of the horizon's reach)."""
        distance, closest, normal = self._closest(guess)
        spaces = []
        for step in range(len(distance)):
            row = []
            for piece, gap in enumerate(distance[step]):
                if gap > self._reach_m:
                    row.append(UNUSED)
                else:
                    n = tuple(normal[step][piece])
                    row.append((n, _dot(n, closest[step][piece]) + self.clearance))
            spaces.append(row)
        return spaces

    def _closest(self, guess: np.ndarray) -> tuple[list, list, list]:
        """What :meth:`StructureProximity.closest` gives, as nested lists: for boxes alone and
        a guess outside every one of them, in plain floats (the same operations in the same
        order, so the same values)."""
        proximity = self.proximity
        if proximity.has_file_mesh:
            return tuple(array.tolist() for array in proximity.closest(guess))
        distance, closest, normal = [], [], []
        for point in np.asarray(guess, dtype=float).tolist():
            gaps, points, normals = [], [], []
            for low, high in self._boxes:
                near = [min(max(point[k], low[k]), high[k]) for k in range(3)]
                out = [point[k] - near[k] for k in range(3)]
                gap = math.sqrt(_dot(out, out))
                if gap == 0.0:  # on or inside a box: the general code
                    return tuple(array.tolist() for array in proximity.closest(guess))
                gaps.append(gap)
                points.append(near)
                normals.append([out[0] / gap, out[1] / gap, out[2] / gap])
            distance.append(gaps)
            closest.append(points)
            normal.append(normals)
        return distance, closest, normal

    def least_slack(
        self, centre: np.ndarray, d_max: float, parameters: np.ndarray, from_start: bool = False
    ) -> float:
        """The least sum of the steps' slacks of a path that ends within d_max of ``centre``
        (each step u of U then within (U - u) d_max of it, u from 0), or with
        ``from_start``, that starts at ``centre`` (step u within (u + 1) d_max of it): where
        a half-space lies beyond its step's ball, the step must break it by at least the gap."""
        normals, offsets = self._unpack(parameters)
        reach = (len(offsets), d_max, from_start)
        radius = self._radii.get(reach)
        if radius is None:
            horizon = len(offsets)
            steps = np.arange(1, horizon + 1) if from_start else horizon - np.arange(horizon)
            radius = self._radii[reach] = (steps * d_max * (1 + 1e-6))[:, None]  # the bounds'
        gap = offsets - normals @ np.asarray(centre, dtype=float) - radius  # tolerance: 1e-6
        return float(np.maximum(gap.max(axis=1), 0.0).sum())

    def slack_guess(self, guess: np.ndarray, parameters: np.ndarray) -> np.ndarray:
        """Each step's largest violation at the guess (the slacks' starting point)."""
        normals, offsets = self._unpack(parameters)
        violation = offsets - np.einsum("usk,uk->us", normals, guess)
        return np.maximum(violation.max(axis=1), 0.0)

    def _unpack(self, parameters: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The (U, slots, 3) normals and (U, slots) offsets of :meth:`parameters`' output."""
        count = len(parameters) // 4
        normals = parameters[: 3 * count].reshape(-1, self.slots, 3)
        return normals, parameters[3 * count :].reshape(-1, self.slots)


def _dot(a, b) -> float:
    """a.b of two 3-vectors, summed left to right (the same on every CPU; numpy's einsum
    sums in an order its SIMD width picks)."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def widened(parameters: np.ndarray, extra_m: float) -> np.ndarray:
    """Margin parameters (:meth:`Margins.parameters`: every slot's normal, then every slot's
    offset) with each used half-space moved ``extra_m`` further out (n.v >= b + extra_m, the
    normals being unit vectors); unused slots (n = 0) stay unused."""
    slots = len(parameters) // 4
    if slots == 0:
        return parameters
    normals = parameters[: 3 * slots].reshape(slots, 3)
    used = np.linalg.norm(normals, axis=1) > 0.5
    out = np.array(parameters, dtype=float)
    out[3 * slots :] += np.where(used, extra_m, 0.0)
    return out
