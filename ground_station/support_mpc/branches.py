"""The terminal link's two branches, and the solve of each: the support MPC's minimum.

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

import numpy as np

from ground_station.support_mpc.margins import Margins
from ground_station.support_mpc.nlp import MARGIN_WEIGHT, SOFT, SupportNlp
from mission.config.settings import ControlSettings

CONVERGED = "SOLVER_RET_SUCCESS"  # casadi's status for a solve that met its tolerance


class TerminalBranches:
    """The NLP's solvers, near and far (each hard, and with margins soft), and the choice
    between them. A solve's parameters: ``fixed`` (yhat, the targets, the terminal waypoint,
    the work UAV's path) and ``flags`` (the LOS anchors, the blocked flags, the map window's
    corner and values, the margins' half-spaces)."""

    def __init__(
        self,
        control: ControlSettings,
        nlp: SupportNlp,
        margins: Margins,
        window_voxels: int,
        with_prior: bool,
    ) -> None:
        """``window_voxels``: how many voxels the map window has; ``with_prior``: whether the
        NLP has the shadow constraint (sigma_0)."""
        self.control = control
        self.horizon = control.horizon_steps
        self.margins = margins
        self._solvers, self._cost = nlp.solvers, nlp.cost
        self._window_voxels = window_voxels
        self.upper_bounds = self._bounds(with_prior)

    def _bounds(self, with_prior: bool) -> dict[str, np.ndarray]:
        """Each solver's constraint rows' upper bounds (every one finite)."""
        control, horizon, slots = self.control, self.horizon, self.margins.slots
        d_max_sq = control.d_max_support_m**2
        steps = np.full(horizon, d_max_sq * (1 + 1e-6))
        shadow = np.full(horizon if with_prior else 0, control.support_max_sigma0_m)
        # Near keeps the terminal strictly inside d_max, so xi's lower weight applies to it;
        # far has no terminal constraint.
        terminal = {"near": [d_max_sq * (1 - 1e-6)], "far": []}
        bounds = {}
        for name in self._solvers:
            soft = name.endswith(SOFT)
            margins = np.zeros(horizon * slots + (horizon if soft else 0))
            branch = name.removesuffix(SOFT)
            bounds[name] = np.concatenate([steps, terminal[branch], shadow, margins])
        return bounds

    def solve(self, fixed: np.ndarray, flags: np.ndarray, guess: np.ndarray):
        """The minimum over both branches of the terminal xi: (path, status, true cost).

        Where near cannot keep a margin (one is out of reach from the terminal waypoint), its
        slacks cost at least ``near_floor``: far is solved first, and near only if far costs
        more (such a near problem is the one fatrop stalls on: 50 iterations for nothing)."""
        c, horizon = self.control, self.horizon
        yhat, terminal = fixed[:3], self.terminal_of(fixed)
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
            g_min = flags[start : start + self._window_voxels].min()
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
        terminal = self.terminal_of(fixed)
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
        result, converged = solver.solve(
            x0=x0,
            p=np.concatenate([fixed, [weight], flags]),
            ubg=self.upper_bounds[form],
        )
        status = CONVERGED if converged else solver.stats()["unified_return_status"]
        path = result["x"][: 3 * self.horizon].reshape(self.horizon, 3)
        terminal_sq = float(np.sum((self.terminal_of(fixed) - path[-1]) ** 2))
        cost = float(result["f"][0]) + (self._xi_weight(terminal_sq) - weight) * terminal_sq
        return path, status, cost

    def terminal_of(self, fixed: np.ndarray) -> np.ndarray:
        """The terminal waypoint w_{n,k_{U+1}} inside the fixed parameters."""
        return fixed[3 + 3 * self.horizon : 6 + 3 * self.horizon]

    def _xi_weight(self, terminal_sq: float) -> float:
        """The paper's xi weight at a squared distance: w_interval up to d_max, else w_penalty."""
        c = self.control
        return c.w_interval if terminal_sq <= c.d_max_support_m**2 else c.w_penalty

    def cost(self, fixed: np.ndarray, flags: np.ndarray, path: np.ndarray) -> float:
        """The true cost of ``path`` (terminal xi on its side of d_max)."""
        terminal_sq = float(np.sum((self.terminal_of(fixed) - path[-1]) ** 2))
        weight = self._xi_weight(terminal_sq)
        return float(self._cost(x=path.ravel(), p=np.concatenate([fixed, [weight], flags]))["f"][0])
