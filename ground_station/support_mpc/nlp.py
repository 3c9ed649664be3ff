"""The support MPC's NLP (paper 4.2.2) as casadi expressions, and its solvers.

Decision variables: the U predicted positions V'_n. Cost, exactly the paper's four terms:

  C_GNSS     = sum_u w_GNSS G_s(v_u)
  C_interval = xi(|yhat - v_1|) + sum_u xi(|v_{u+1} - v_u|) + xi(|w_{n,k_{U+1}} - v_U|),
               xi(d) = w_interval d^2 if d <= d_max else w_penalty d^2
  C_waypoint = sum_u w_waypoint |v_u - w_{n,k_u}|^2
  C_relative = sum_u (w_relative, or w_penalty if not observable) |v^(w)_u - v_u|^2

With margins (``control.min_separation_m`` or ``control.clearance_m`` above zero), each step
u must also lie in ``slots`` half-spaces n.v_u >= b (the other UAVs' and the structure's,
linearised at the guess: :mod:`ground_station.support_mpc.margins`), in two forms: *hard*, as
constraints, and *soft*, as an exact L1 penalty (one slack s_u >= 0 per step relaxes every
half-space of that step, at MARGIN_WEIGHT per metre in the cost). The soft problem is always
feasible, and where the margins can be kept its slacks are zero (the weight exceeds any
multiplier the other terms can produce): it has the hard problem's minimum there. The hard
one is cheaper to solve (15 variables and no slack rows, against 20 and 5 more: fewer and
cheaper iterations), so it is solved first and the soft one only where it fails (see
:mod:`ground_station.support_mpc.mpc`).

Each step is also bounded hard by d_max (the vehicle cannot fly faster), where xi is exactly
w_interval d^2; the terminal link keeps the jump at d_max, which the solver sees as two smooth
NLPs, *near* (|w - v_U| <= d_max, weight w_interval) and *far* (weight w_penalty): see
:mod:`ground_station.support_mpc.mpc`. G_s enters as the explicit eight-corner sum of
:func:`~ground_station.estimation.gnss_map.casadi_hermite` over a window of voxels around yhat_n,
so the solver gets exact second derivatives.
"""

from __future__ import annotations

import contextlib
import functools
import sys
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ground_station.estimation import gnss_map
from ground_station.estimation.gnss_map import inlined_hermite
from ground_station.support_mpc.nlp_cache import KeyedBuild, NlpBuild, compiled_libraries
from mission.codegen import casadi_cache, lean_gradient
from mission.codegen.build_key import build_key
from mission.codegen.casadi_buffer import BufferedFunction
from mission.config.settings import ControlSettings
from mission.world import grid
from mission.world.grid import VoxelGrid

IPOPT_OPTIONS = {
    "ipopt.print_level": 0,
    "ipopt.sb": "yes",
    "print_time": False,
    "calc_lam_p": False,  # unused; its gradient over the G window costs more than the solve
    "ipopt.max_iter": 50,
    "ipopt.tol": 1e-4,  # positions to ~0.1 mm; 1e-6 cost 25 % more iterations for nothing
    "ipopt.acceptable_tol": 1e-4,
    "ipopt.warm_start_init_point": "yes",
    "ipopt.hessian_approximation": "exact",  # measured: 3x fewer ms than L-BFGS here
    # MUMPS's matching-based permutation and scaling are for hard large systems; here they
    # cost 5 % of a solve and change the solutions by 1e-14 (600 recorded problems)
    "ipopt.mumps_permuting_scaling": 0,
    "error_on_fail": True,  # a failure raises (caught): a success needs no look at stats()
}
# fatrop runs IPOPT's algorithm (filter line search, same barrier defaults) without IPOPT's
# per-solve set-up of its objects and of MUMPS, which is ~90 % of a 15-variable solve: 3x
# fewer ms. One dense stage ("none") is all 15 variables need.
FATROP_OPTIONS = {
    "structure_detection": "none",
    "print_time": False,
    "calc_lam_p": False,
    "error_on_fail": True,  # a failure raises (caught): a success needs no look at stats()
    # bound_push as IPOPT's warm start has it: the guess is the previous plan, shifted
    "fatrop": {"print_level": 0, "tol": 1e-4, "max_iter": 50, "bound_push": 1e-3},
}
SOLVER_OPTIONS = {"fatrop": FATROP_OPTIONS, "ipopt": IPOPT_OPTIONS}
MARGIN_WEIGHT = 1.0e4  # cost per metre of a margin's violation (the exact penalty's weight)
SOFT = "_soft"  # the suffix of a branch's solver with the margins as an exact penalty
# The code the NLPs' cache key covers: this module, G's interpolant and its grid, and how the
# C is generated (a test traces the build for any other module of the project it runs).
NLP_BUILT_BY = (sys.modules[__name__], gnss_map, grid, lean_gradient, casadi_cache)


@dataclass(frozen=True)
class NlpSymbols:
    """The decision variables and the parameters of the support MPC's NLP."""

    v: ca.MX  # (3, U) the predicted positions
    yhat: ca.MX
    targets: ca.MX  # (3, U) w_{n,k_u}
    terminal: ca.MX  # w_{n,k_{U+1}}
    work: ca.MX  # (3, U) the work UAV's predicted path
    anchors: ca.MX  # (3, U) where a blocked step is pulled (see support_mpc.los_anchors)
    blocked: ca.MX  # (U,) 1 where the step is not observable
    values: ca.MX  # G over the window
    prior: ca.MX  # sigma_0 over the window (empty without the shadow constraint)
    corner: ca.MX  # the window's corner, world coordinates
    terminal_weight: ca.MX  # xi's weight on the branch being solved
    normals: ca.MX  # (3, U slots) the margins' half-spaces n.v_u >= b, step by step
    offsets: ca.MX  # (U slots,) their b
    slack: ca.MX  # (U,) how far each step may break its margins (empty without margins)

    @classmethod
    def make(cls, horizon: int, n_window: int, with_prior: bool, slots: int = 0) -> NlpSymbols:
        """Fresh symbols for a horizon of U steps, a window of ``n_window`` voxels and
        ``slots`` margin half-spaces per step."""
        sym = ca.MX.sym
        return cls(
            v=sym("v", 3, horizon),
            yhat=sym("yhat", 3),
            targets=sym("w", 3, horizon),
            terminal=sym("terminal", 3),
            work=sym("vw", 3, horizon),
            anchors=sym("q", 3, horizon),
            blocked=sym("blocked", horizon),
            values=sym("G", n_window),
            prior=sym("sigma0", n_window if with_prior else 0),
            corner=sym("corner", 3),
            terminal_weight=sym("w_terminal"),
            normals=sym("n", 3, horizon * slots),
            offsets=sym("b", horizon * slots),
            slack=sym("s", horizon if slots else 0),
        )

    def parameters(self) -> ca.MX:
        """Every parameter in the order the solver takes them (the window's values last)."""
        return ca.vertcat(
            self.yhat,
            ca.vec(self.targets),
            self.terminal,
            ca.vec(self.work),
            self.terminal_weight,
            ca.vec(self.anchors),
            self.blocked,
            self.corner,
            self.values,
            self.prior,
            *([ca.vec(self.normals), self.offsets] if self.offsets.shape[0] else []),
        )

    def variables(self, soft: bool) -> ca.MX:
        """The decision variables: the path, then (soft margins) the margins' slacks."""
        if not soft:
            return ca.vec(self.v)
        return ca.vertcat(ca.vec(self.v), self.slack)

    def margin_rows(self, slots: int, soft: bool) -> list[ca.MX]:
        """b - n.v_u <= 0 for every half-space; soft: b - n.v_u - s_u <= 0, then -s_u <= 0."""
        horizon = self.v.shape[1]
        rows = [
            self.offsets[u * slots + j]
            - ca.dot(self.normals[:, u * slots + j], self.v[:, u])
            - (self.slack[u] if soft else 0)
            for u in range(horizon)
            for j in range(slots)
        ]
        return rows + ([-self.slack[u] for u in range(horizon)] if soft else [])


@dataclass(frozen=True)
class SupportNlp:
    """The solvers of the near and far branches (with margins: hard, and soft under the names
    with SOFT) and the cost as a function of (x, p)."""

    solvers: dict[str, BufferedFunction]
    cost: BufferedFunction


def build_support_nlp(
    control: ControlSettings,
    window: VoxelGrid,
    with_prior: bool,
    compiled: bool = True,
    slots: int = 0,
) -> SupportNlp:
    """The NLP over a window of voxels with ``slots`` margin half-spaces per step (none: the
    paper's problem), its functions compiled when a C compiler is there (and ``compiled`` asks
    for it; else casadi interprets them: the same plans, slower). Compiled libraries are
    cached under a key from these arguments and the code that builds the NLP
    (:data:`NLP_BUILT_BY`): a cached one loads without the NLP being built."""
    symbolic = functools.cache(lambda: _symbolic_nlps(control, window, with_prior, slots))
    forms = ["near", "far"] + (["near" + SOFT, "far" + SOFT] if slots else [])
    plugin = control.mpc_solver
    options = SOLVER_OPTIONS[plugin]
    key = nlp_key(control, window, with_prior, slots)

    def build(form: str) -> NlpBuild:
        return NlpBuild(f"support_mpc_{form}", plugin, symbolic()[0][form], options)

    builds = [
        KeyedBuild(f"support_mpc_{form}", key, functools.partial(build, form)) for form in forms
    ]
    unbounded = {"lbx": -np.inf, "ubx": np.inf, "lbg": -np.inf}
    interpreted = contextlib.nullcontext([None] * len(builds))
    with compiled_libraries(builds) if compiled else interpreted as libraries:
        solvers = {}
        for form, build_of, library in zip(forms, builds, libraries, strict=True):
            loaded = symbolic()[0][form] if library is None else library
            solver = ca.nlpsol(build_of.part, plugin, loaded, options)
            solvers[form] = BufferedFunction(solver, ("x", "f"), unbounded)
        # near's own f(x, p) is the cost: compiled, its library's "nlp" (f and g)
        cost = symbolic()[1] if libraries[0] is None else ca.external("nlp", libraries[0])
    return SupportNlp(solvers, BufferedFunction(cost, ("f",)))


def nlp_key(control: ControlSettings, window: VoxelGrid, with_prior: bool, slots: int) -> str:
    """The libraries' cache key: every argument the NLPs are built from (the window whole, its
    origin included), the solver's options and the code that builds them."""
    plugin = control.mpc_solver
    return build_key(
        [control, window, with_prior, slots, plugin, SOLVER_OPTIONS[plugin]], NLP_BUILT_BY
    )


def _symbolic_nlps(
    control: ControlSettings, window: VoxelGrid, with_prior: bool, slots: int
) -> tuple[dict[str, dict[str, ca.MX]], ca.Function]:
    """Each form's NLP (keys x, p, f, g) by name, and the cost as a function of (x, p)."""
    horizon = control.horizon_steps
    s = NlpSymbols.make(horizon, window.n_voxels, with_prior, slots)
    hermite = inlined_hermite(window)  # G_s and the prior's, per step
    cost = _cost(control, s, hermite)
    terminal_sq = ca.sumsqr(s.terminal - s.v[:, horizon - 1])
    cost += s.terminal_weight * terminal_sq
    parameters = s.parameters()
    # The vehicle cannot fly faster than s_max: each predicted step is also bounded hard
    # (the paper's penalty alone lets a discontinuous cost trap the solver beyond d_max).
    steps = [ca.sumsqr(s.v[:, 0] - s.yhat)]
    steps += [ca.sumsqr(s.v[:, u + 1] - s.v[:, u]) for u in range(horizon - 1)]
    # Stay where the prior map (structure and sky, no zones) predicts a usable fix: the
    # paper's LOS penalty pulls a blocked support straight at the work UAV, i.e. under the
    # deck, where it would lose its fix (and fly into the structure).
    shadow = [hermite(s.v[:, u] - s.corner, s.prior) for u in range(horizon)] if with_prior else []
    cost_function = ca.Function(
        "support_mpc_cost", [ca.vec(s.v), parameters], [cost], ["x", "p"], ["f"]
    )
    # With an infinite bound on far's terminal row fatrop failed 99 of 1,220 recorded solves
    # and carried the failure into the solves after it (plans then depended on the order of
    # solving); without the row it solves them all, as IPOPT does. No bound of either branch
    # is infinite.
    nlps = {}
    for soft in (False, True) if slots else (False,):
        margins = s.margin_rows(slots, soft) if slots else []
        objective = cost + MARGIN_WEIGHT * ca.sum1(s.slack) if soft else cost
        rows = {
            "near": ca.vertcat(*steps, terminal_sq, *shadow, *margins),
            "far": ca.vertcat(*steps, *shadow, *margins),
        }
        for branch, g in rows.items():
            name = branch + SOFT if soft else branch
            nlps[name] = {"x": s.variables(soft), "p": parameters, "f": objective, "g": g}
    return nlps, cost_function


def _cost(control: ControlSettings, s: NlpSymbols, hermite: ca.Function) -> ca.MX:
    """The paper's cost but the terminal link (solved per branch). Steps are bounded hard,
    where xi(d) = w_interval d^2 exactly: writing it so keeps the cost smooth."""
    c, v = control, s.v
    horizon = control.horizon_steps
    cost = c.w_interval * ca.sumsqr(s.yhat - v[:, 0])
    for u in range(horizon):
        cost += c.w_gnss * hermite(v[:, u] - s.corner, s.values)
        cost += c.w_waypoint * ca.sumsqr(v[:, u] - s.targets[:, u])
        cost += (1 - s.blocked[u]) * c.w_relative * ca.sumsqr(s.work[:, u] - v[:, u])
        cost += s.blocked[u] * c.w_penalty * ca.sumsqr(s.anchors[:, u] - v[:, u])
        if u + 1 < horizon:
            cost += c.w_interval * ca.sumsqr(v[:, u + 1] - v[:, u])
    return cost
