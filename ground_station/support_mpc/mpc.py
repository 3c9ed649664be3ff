"""MPC of each support UAV (paper 4.2.2): its NLP (:mod:`ground_station.support_mpc.nlp`) solved
with casadi + fatrop (or IPOPT), built once per run, for any support with its own parameters.

Observability (range and line of sight between V^(w)_u and v_u) is not differentiable: it is
evaluated on the initial guess (the previous solution shifted by one step), held fixed during
the solve, and the problem is solved once more if the solution's flags differ (MODEL.md),
with a step blocked at either held blocked: taking the solution's flags alone flip-flops
between two paths, each blocked where the other's flags say it is not.

The terminal xi jumps at d_max, and an interior-point solver cycles across a jump until its
iteration limit. Its minimum is found exactly from two smooth problems instead: *near*
(|w - v_U| <= d_max, weight w_interval) and *far* (no bound, weight w_penalty). The lower of
the two, costed with the true xi, is the minimum: far's optimum is either beyond d_max (then
it is the far side's minimum) or within it (then near is at least as good). Far is skipped
when near's cost is below any cost the far side can have (w_penalty d_max^2 + w_GNSS U
min G), or when the terminal is out of reach, where only far is feasible.

With margins each branch is solved with them as constraints (*hard*) where no step's
half-space is out of its reach (from yhat, and for near from the terminal: a necessary
condition of feasibility), and with them as an exact penalty (*soft*) where one is or where
the hard solve fails: the same minimum where the margins can be kept, for less time (about
a quarter less time a plan than the soft problem alone; `mission bench --only margins`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ground_station.support_mpc.los_anchors import LosAnchors
from ground_station.support_mpc.margins import Margins, widened
from ground_station.support_mpc.nlp import MARGIN_WEIGHT, SOFT, build_support_nlp
from mission.config.resources import mpc_window_shape
from mission.config.settings import ControlSettings
from mission.world.camera import CameraModel
from mission.world.grid import VoxelGrid

ESCAPE_STARTS = 1  # escape starts solved: the cheapest of six where it starts
CONVERGED = "SOLVER_RET_SUCCESS"  # casadi's status for a solve that met its tolerance


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
        slots = self.margins.slots
        nlp = build_support_nlp(control, self._window_grid, with_prior, compiled, slots)
        self._solvers, self._cost = nlp.solvers, nlp.cost
        self._anchors = LosAnchors(control, camera, grid, self.sigma0)
        d_max_sq = control.d_max_support_m**2
        steps = np.full(self.horizon, d_max_sq * (1 + 1e-6))
        shadow = np.full(0 if sigma0 is None else self.horizon, control.support_max_sigma0_m)
        # Near keeps the terminal strictly inside d_max, so xi's lower weight applies to it;
        # far has no terminal constraint.
        terminal = {"near": [d_max_sq * (1 - 1e-6)], "far": []}
        self._upper_bounds = {}
        for name in self._solvers:
            soft = name.endswith(SOFT)
            margins = np.zeros(self.horizon * slots + (self.horizon if soft else 0))
            branch = name.removesuffix(SOFT)
            self._upper_bounds[name] = np.concatenate([steps, terminal[branch], shadow, margins])

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
        path, status, cost = self._solve_once(fixed, flags, guess)
        if request.escape:  # G_s is flat at voxel centres: also start from paths leaving each way
            for candidate in self._escape_guesses(yhat, fixed, flags):
                tried = self._solve_once(fixed, flags, candidate)
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
            path, status, _ = self._solve_once(fixed, flags, path)
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

    def _solve_once(self, fixed: np.ndarray, flags: np.ndarray, guess: np.ndarray):
        """The minimum over both branches of the terminal xi: (path, status, true cost).

        Where near cannot keep a margin (one is out of reach from the terminal waypoint), its
        slacks cost at least ``near_floor``: far is solved first, and near only if far costs
        more (such a near problem is the one fatrop stalls on: 50 iterations for nothing)."""
        c, horizon = self.control, self.horizon
        yhat, terminal = fixed[:3], self._terminal_of(fixed)
        reach = (horizon + 1) * c.d_max_support_m
        best = far = None
        if np.linalg.norm(terminal - yhat) <= reach:
            near_floor = self._near_floor(terminal, flags)
            if near_floor > 0:
                far = self._solve_branch(fixed, flags, guess, "far")
                if far[1] == CONVERGED and far[2] <= near_floor:
                    return far
            best = self._solve_branch(fixed, flags, guess, "near")
            start = 3 * horizon + horizon + 3  # G's window, after the anchors, flags, corner
            g_min = flags[start : start + self._window_grid.n_voxels].min()
            far_floor = c.w_penalty * c.d_max_support_m**2 + c.w_gnss * horizon * g_min
            if best[1] == CONVERGED and best[2] <= far_floor:
                return best
        if far is None:
            far = self._solve_branch(fixed, flags, guess, "far")
        tried = [plan for plan in (best, far) if plan is not None]
        converged = [plan for plan in tried if plan[1] == CONVERGED]
        return min(converged or tried, key=lambda plan: plan[2])

    def _near_floor(self, terminal: np.ndarray, flags: np.ndarray) -> float:
        """A lower bound of near's cost from its margins' slacks (0 without margins)."""
        if not self.margins.slots:
            return 0.0
        return MARGIN_WEIGHT * self.margins.least_slack(
            terminal, self.control.d_max_support_m, self._margin_flags(flags)
        )

    def _margin_flags(self, flags: np.ndarray) -> np.ndarray:
        """The margins' parameters, the last of the flags."""
        return flags[len(flags) - self.horizon * self.margins.slots * 4 :]

    def _solve_branch(self, fixed, flags, guess, branch: str):
        """One branch's solve from ``guess``: (path, casadi's status, true cost). With
        margins: hard where they may be kept, soft where they cannot or the hard solve fails."""
        if not self.margins.slots:
            return self._solve_form(fixed, flags, guess, branch, branch)
        if self._may_keep_margins(fixed, flags, branch):
            hard = self._solve_form(fixed, flags, guess, branch, branch)
            if hard[1] == CONVERGED:
                return hard
        return self._solve_form(fixed, flags, guess, branch, branch + SOFT)

    def _may_keep_margins(self, fixed, flags, branch: str) -> bool:
        """Whether every step's half-spaces are within its reach: from yhat (step u within
        (u + 1) d_max of it) and, for near, from the terminal waypoint."""
        margins, d_max = self.margins, self.control.d_max_support_m
        parameters = self._margin_flags(flags)
        if margins.least_slack(fixed[:3], d_max, parameters, from_start=True) > 0:
            return False
        terminal = self._terminal_of(fixed)
        return branch == "far" or margins.least_slack(terminal, d_max, parameters) == 0

    def _solve_form(self, fixed, flags, guess, branch: str, form: str):
        """``branch``'s solve from ``guess`` with the solver ``form`` (the branch, or its soft
        form): (path, casadi's status, true cost)."""
        c = self.control
        solver = self._solvers[form]
        weight = c.w_interval if branch == "near" else c.w_penalty
        x0 = guess.ravel()
        if form.endswith(SOFT):  # the slacks start at each step's violation of its margins
            slacks = self.margins.slack_guess(guess, self._margin_flags(flags))
            x0 = np.concatenate([x0, slacks + 1e-3])
        result = solver(
            x0=x0,
            p=np.concatenate([fixed, [weight], flags]),
            ubg=self._upper_bounds[form],
        )
        status = solver.stats()["unified_return_status"]
        path = result["x"][: 3 * self.horizon].reshape(self.horizon, 3)
        terminal_sq = float(np.sum((self._terminal_of(fixed) - path[-1]) ** 2))
        cost = float(result["f"][0]) + (self._xi_weight(terminal_sq) - weight) * terminal_sq
        return path, status, cost

    def _terminal_of(self, fixed: np.ndarray) -> np.ndarray:
        """The terminal waypoint w_{n,k_{U+1}} inside the fixed parameters."""
        return fixed[3 + 3 * self.horizon : 6 + 3 * self.horizon]

    def _xi_weight(self, terminal_sq: float) -> float:
        """The paper's xi weight at a squared distance: w_interval up to d_max, else w_penalty."""
        c = self.control
        return c.w_interval if terminal_sq <= c.d_max_support_m**2 else c.w_penalty

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
        terminal = self._terminal_of(fixed)
        out = (horizon + 1) // 2
        paths = []
        for direction in np.vstack([np.eye(3), -np.eye(3)]):
            leaving = yhat + np.arange(1, out + 1)[:, None] * d_max * direction
            back = np.arange(1, horizon - out + 1)[:, None] / (horizon - out + 1)
            paths.append(np.vstack([leaving, leaving[-1] + (terminal - leaving[-1]) * back]))
        costs = [self.cost(fixed, flags, path) for path in paths]
        return [paths[i] for i in np.argsort(costs, kind="stable")[:ESCAPE_STARTS]]

    def cost(self, fixed: np.ndarray, flags: np.ndarray, path: np.ndarray) -> float:
        """The true cost of ``path`` (terminal xi on its side of d_max)."""
        terminal_sq = float(np.sum((self._terminal_of(fixed) - path[-1]) ** 2))
        weight = self._xi_weight(terminal_sq)
        return float(self._cost(x=path.ravel(), p=np.concatenate([fixed, [weight], flags]))["f"][0])
