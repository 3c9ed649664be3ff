"""MPC of each support UAV (paper 4.2.2): its NLP (:mod:`ground_station.support_mpc.nlp`) solved
with casadi + fatrop (or IPOPT), built once per run, for any support with its own parameters.

Observability (range and line of sight between V^(w)_u and v_u) is not differentiable: it is
evaluated on the initial guess (the previous solution shifted by one step), held fixed during
the solve, and the problem is solved once more if the solution's flags differ
(docs/ground-station.md, "The support MPC"), with a step blocked at either held blocked:
taking the solution's flags alone flip-flops between two paths, each blocked where the
other's flags say it is not.

Each solve is the minimum over the terminal link's two branches, near and far, each solved
with its margins hard or soft (:mod:`ground_station.support_mpc.branches`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ground_station.support_mpc.branches import TerminalBranches
from ground_station.support_mpc.los_anchors import LosAnchors
from ground_station.support_mpc.margins import Margins, widened
from ground_station.support_mpc.nlp import build_support_nlp
from mission.config.resources import mpc_window_shape
from mission.config.settings import ControlSettings
from mission.world.camera import CameraModel
from mission.world.grid import VoxelGrid

ESCAPE_STARTS = 1  # escape starts solved: the cheapest of six where it starts


@dataclass(frozen=True)
class PlanRequest:
    """One support's MPC problem: its estimate, the waypoints its horizon aims at, the work
    UAV's predicted path, the map window (corner; G's and sigma_0's values), the warm start."""

    name: str
    yhat: np.ndarray
    targets: np.ndarray  # (U, 3): w_{n,k_u}
    terminal: np.ndarray  # w_{n,k_{U+1}}
    work: np.ndarray  # (U, 3): the work UAV's predicted path
    corner: np.ndarray
    window: np.ndarray
    warm_start: np.ndarray | None
    escape: bool
    others: np.ndarray | None = None  # (m, U, 3): the other UAVs' predicted positions
    widen_m: float = 0.0  # every margin this much wider (an excluded support: integrity)


@dataclass(frozen=True)
class SupportPlan:
    """The optimised local path V_n (U, 3) and how the solve went."""

    path: np.ndarray
    status: str
    solve_ms: float
    blocked: np.ndarray
    resolved: bool
    anchors: np.ndarray

    @property
    def command(self) -> np.ndarray:
        """The movement command: the first predicted position."""
        return self.path[0]


class SupportMpc:
    """One NLP, built once, solved for any support with its own parameters.

    G (and sigma_0, for the shadow constraint) enter through a cube of voxels around yhat_n,
    wide enough for everything the horizon can reach (U d_max plus a margin on each side), so
    a solve passes a few thousand values rather than the whole map; the cube's corner is a
    parameter.
    """

    def __init__(
        self,
        control: ControlSettings,
        grid: VoxelGrid,
        camera: CameraModel,
        sigma0: np.ndarray | None = None,
        compiled: bool = True,
        others: int = 0,
    ) -> None:
        """``others``: how many other UAVs a support keeps its separation from (the work UAV
        and the other supports); ``compiled=False``: casadi interprets the NLP, even with a C
        compiler (slower, the same plans)."""
        self.control = control
        self.grid = grid
        self.camera = camera
        self.sigma0 = (
            None if sigma0 is None else np.asarray(sigma0, dtype=float).reshape(grid.shape)
        )
        self.horizon = control.horizon_steps
        self.window = mpc_window_shape(control, grid.voxel_m, grid.shape)
        self._window_grid = VoxelGrid(np.zeros(3), grid.voxel_m, self.window)
        with_prior = sigma0 is not None
        structure = camera.structure
        if structure is None:
            raise ValueError("the support MPC needs the camera's structure for its margins")
        self.margins = Margins(control, structure, others, compiled)
        nlp = build_support_nlp(
            control, self._window_grid, with_prior, compiled, self.margins.slots
        )
        self.branches = TerminalBranches(
            control, nlp, self.margins, self._window_grid.n_voxels, with_prior
        )
        self._anchors = LosAnchors(control, camera, grid, self.sigma0)

    def window_of(self, yhat: np.ndarray, g_values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(corner of the window in world coordinates, the values the NLP takes there: G's
        and then sigma_0's, each first-axis-fastest)."""
        shape = np.array(self.grid.shape)
        size = np.array(self.window)
        centre = self.grid.index_of(np.asarray(yhat)[None])[0]
        low = np.clip(centre - size // 2, 0, shape - size)
        cube = tuple(slice(low[a], low[a] + size[a]) for a in range(3))
        corner = self.grid.origin_m + self.grid.voxel_m * low
        maps = [np.asarray(g_values).reshape(self.grid.shape)[cube].ravel(order="F")]
        if self.sigma0 is not None:
            maps.append(self.sigma0[cube].ravel(order="F"))
        return corner, np.concatenate(maps)

    def solve(
        self,
        yhat: np.ndarray,
        support_waypoints: np.ndarray,
        work_path: np.ndarray,
        work_indices: np.ndarray,
        g_values: np.ndarray,
        observable,
        warm_start: np.ndarray | None = None,
        escape: bool = False,
    ) -> SupportPlan:
        """Optimise V_n (``g_values``: G as a 3-D array; ``observable(a, b)``: rows of b
        observable from rows of a)."""
        return self.plan(
            self.request(
                "", yhat, support_waypoints, work_path, work_indices, g_values, warm_start, escape
            ),
            observable,
        )

    def request(
        self,
        name: str,
        yhat: np.ndarray,
        support_waypoints: np.ndarray,
        work_path: np.ndarray,
        work_indices: np.ndarray,
        g_values: np.ndarray,
        warm_start: np.ndarray | None = None,
        escape: bool = False,
        others: np.ndarray | None = None,
        widen_m: float = 0.0,
    ) -> PlanRequest:
        """Everything one support's solve needs, G cut down to the window around yhat;
        ``others`` (m, U, 3): the other UAVs' predicted positions, for the separation;
        ``widen_m``: how much wider than the scenario's its margins are."""
        horizon = self.horizon
        corner, window = self.window_of(yhat, g_values)
        return PlanRequest(
            name,
            np.asarray(yhat, dtype=float),
            support_waypoints[work_indices[:horizon]],
            support_waypoints[work_indices[horizon]],
            work_path[:horizon],
            corner,
            window,
            warm_start,
            escape,
            others,
            widen_m,
        )

    def plan(self, request: PlanRequest, observable) -> SupportPlan:
        """Optimise V_n for one request (``observable(a, b)``: rows of b observable from rows
        of a)."""
        yhat, targets, terminal, work = (
            request.yhat,
            request.targets,
            request.terminal,
            request.work,
        )
        corner, window = request.corner, request.window
        fixed = np.concatenate([yhat, targets.ravel(), terminal, work.ravel()])
        guess = self._initial_guess(yhat, terminal, request.warm_start)
        start = time.perf_counter()
        blocked = ~observable(guess, work)
        anchors = self.anchors(guess, work, targets, blocked)
        margins = self._margin_parameters(request, guess)
        flags = np.concatenate([anchors.ravel(), blocked.astype(float), corner, window, margins])
        path, status, cost = self.branches.solve(fixed, flags, guess)
        if request.escape:  # G_s is flat at voxel centres: also start from paths leaving each way
            for candidate in self._escape_guesses(yhat, fixed, flags):
                tried = self.branches.solve(fixed, flags, candidate)
                if tried[2] < cost - 1e-9:
                    path, status, cost = tried
        resolved = False
        after = ~observable(path, work)
        if np.any(after != blocked):
            blocked, resolved = blocked | after, True  # blocked either way: held blocked
            anchors = self.anchors(path, work, targets, blocked)
            margins = self._margin_parameters(request, path)
            flags = np.concatenate(
                [anchors.ravel(), blocked.astype(float), corner, window, margins]
            )
            path, status, _ = self.branches.solve(fixed, flags, path)
        elapsed = (time.perf_counter() - start) * 1000
        return SupportPlan(path, status, elapsed, blocked, resolved, anchors)

    def _margin_parameters(self, request: PlanRequest, guess: np.ndarray) -> np.ndarray:
        """The margins' half-spaces linearised at ``guess`` (none without margins)."""
        others = np.zeros((0, self.horizon, 3)) if request.others is None else request.others
        spaces = self.margins.parameters(guess, request.yhat, others)
        return widened(spaces, request.widen_m) if request.widen_m > 0 else spaces

    def _initial_guess(
        self, yhat: np.ndarray, terminal: np.ndarray, warm_start: np.ndarray | None
    ) -> np.ndarray:
        if warm_start is not None:
            return np.vstack([warm_start[1:], warm_start[-1:]])
        fractions = np.arange(1, self.horizon + 1)[:, None] / (self.horizon + 1)
        return yhat + (terminal - yhat) * fractions

    def anchors(
        self, guess: np.ndarray, work: np.ndarray, targets: np.ndarray, blocked: np.ndarray
    ) -> np.ndarray:
        """Where the LOS penalty pulls each blocked step
        (:mod:`ground_station.support_mpc.los_anchors`)."""
        return self._anchors(guess, work, targets, blocked)

    def _escape_guesses(self, yhat: np.ndarray, fixed: np.ndarray, flags: np.ndarray):
        """Paths leaving at d_max per step along +-x, +-y or +-z for half the horizon, then
        heading straight for the terminal waypoint: the ESCAPE_STARTS of the six that cost
        least where they start."""
        horizon, d_max = self.horizon, self.control.d_max_support_m
        terminal = self.branches.terminal_of(fixed)
        out = (horizon + 1) // 2
        paths = []
        for direction in np.vstack([np.eye(3), -np.eye(3)]):
            leaving = yhat + np.arange(1, out + 1)[:, None] * d_max * direction
            back = np.arange(1, horizon - out + 1)[:, None] / (horizon - out + 1)
            paths.append(np.vstack([leaving, leaving[-1] + (terminal - leaving[-1]) * back]))
        costs = [self.branches.cost(fixed, flags, path) for path in paths]
        return [paths[i] for i in np.argsort(costs, kind="stable")[:ESCAPE_STARTS]]
