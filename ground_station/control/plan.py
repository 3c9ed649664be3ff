"""Step 5 of the control cycle, plan: the work UAV's path by Algorithm 1 (:func:`plan`), then
each support's MPC posed around it and solved (:func:`solve_supports`).

The two are apart so the work UAV's command, which does not depend on the supports' plans, can
leave before their problems are even posed.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ground_station.control.run_context import RunContext
from ground_station.control.work_mpc import WorkPrediction, hold_work, predict_work
from ground_station.roles.allocation import routed_plans
from ground_station.state.station_state import StationState
from ground_station.support_mpc.mpc import PlanRequest, SupportPlan

ESCAPE_MARGIN_M = 0.25  # G_s this far above its start at yhat: try escape starts too


@dataclass(frozen=True)
class FormationPlan:
    """The work UAV's predicted path, and the supports whose MPCs are to be solved around it."""

    work: WorkPrediction
    supports: tuple[str, ...]


def plan(
    state: StationState, context: RunContext, supports: Sequence[str], hold: bool = False
) -> FormationPlan:
    """The work UAV's path from xhat (its command is the first point), for ``supports`` to
    plan around; records the work UAV's commanded displacement in ``state``.

    The work UAV waits (holds) where its next step would break a margin
    (:func:`work_must_wait`). ``hold`` (a blind cycle: no support contributed): it holds where
    its last command took it (xhat, dead-reckoned there by the fusion) for the whole horizon, so the
    supports plan around a work UAV that stays put and regain sight of it."""
    control = context.scenario.control
    if hold:
        work = hold_work(state.xhat, state.k, control.horizon_steps)
    else:
        work = predict_work(
            state.xhat,
            state.k,
            context.work_waypoints,
            control.horizon_steps,
            control.d_max_work_m,
            control.arrival_tol_m,
        )
    if not hold and work_must_wait(state, work.command, context):
        work = hold_work(state.xhat, state.k, control.horizon_steps)
    reach = control.s_max_work_m_s * control.t_cont_s
    state.last_work_command = reachable(state.xhat, work.command, reach)
    return FormationPlan(work, tuple(supports))


def reachable(start: np.ndarray, target: np.ndarray, reach: float) -> np.ndarray:
    """The displacement a vehicle makes toward ``target`` in one cycle, at most ``reach``."""
    move = target - start
    distance = float(np.linalg.norm(move))
    return move if distance <= reach else move * (reach / distance)


def work_must_wait(state: StationState, command: np.ndarray, context: RunContext) -> bool:
    """Whether the work UAV's next step would bring it inside a margin it is not already
    inside, closer: within the separation of a support's estimate, or within the clearance
    of the structure or the ground. It then waits for the supports to give way."""
    control = context.scenario.control
    if control.min_separation_m > 0:
        for yhat in state.yhat.values():
            after = float(np.linalg.norm(command - yhat))
            if after < control.min_separation_m and after < np.linalg.norm(state.xhat - yhat):
                return True
    if control.clearance_m > 0:
        proximity = context.support_mpc.margins.proximity
        after, now = proximity.clearance(np.vstack([command, state.xhat]))
        return bool(after < control.clearance_m and after < now)
    return False


def solve_supports(
    state: StationState, formation: FormationPlan, context: RunContext
) -> dict[str, SupportPlan]:
    """Every support's MPC posed around the work UAV's path and solved (here, or shared with
    the helper process); each plan's commanded displacement and path (the next warm start) go
    into ``state``."""
    work = formation.work
    control = context.scenario.control
    reach = control.s_max_support_m_s * control.t_cont_s
    # a support blown far outside the workspace is brought back straight, not planned: the MPC's
    # map and margins hold inside it (and a solve posed far outside can fail to return)
    lost = {n for n in formation.supports if not _near_workspace(state.yhat[n], context)}
    requests = [
        support_request(state, name, work, context)
        for name in formation.supports
        if name not in lost
    ]
    plans = context.planner.plan_all(requests)
    plans.update(routed_plans(state, context, state.allocation))  # supports off the formation
    for name in sorted(lost):
        plans[name] = _straight_back(state, name, context, reach)
    for name, support_plan in list(plans.items()):
        if not _plausible(support_plan.path, state.yhat[name], reach):
            plans[name] = _held(support_plan, state.yhat[name])  # a diverged solve: hold
    for name, support_plan in plans.items():
        state.last_support_command[name] = reachable(state.yhat[name], support_plan.command, reach)
        if support_plan.status == REJECTED:  # no warm start from it
            state.warm.pop(name, None)
        else:
            state.warm[name] = support_plan.path
    return plans


def support_request(
    state: StationState, name: str, work: WorkPrediction, context: RunContext
) -> PlanRequest:
    """One support's MPC problem; with escape starts where G says GNSS is worse than the prior
    map expected."""
    yhat = state.yhat[name]
    g = context.g
    now, initial = g.smoothed_with_initial(yhat)
    risen = bool(now[0] > float(initial[0]) + ESCAPE_MARGIN_M)
    escape = risen and context.scenario.control.escape_starts
    return context.support_mpc.request(
        name,
        yhat,
        context.support_waypoints[name],
        work.path,
        work.indices,
        g.values,
        state.warm.get(name),
        escape=escape,
        others=others_predicted(state, name, work, context.scenario.control.horizon_steps),
        widen_m=_widened_by(context, name),
    )


def _widened_by(context: RunContext, name: str) -> float:
    """How much wider than the scenario's a support's margins are (the integrity monitor's
    doubt; 0 where it is off)."""
    if context.integrity is None:
        return 0.0
    return context.integrity.extra_margin_m(name, context.scenario.control.estimate_allowance_m)


def others_predicted(
    state: StationState, name: str, work: WorkPrediction, horizon: int
) -> np.ndarray:
    """(m, U, 3): where the other UAVs are predicted at a support's steps: the work UAV on its
    path, each other support on its last plan shifted by a step (held at its estimate before
    it has one)."""
    others = [work.path[:horizon]]
    for other, yhat in state.yhat.items():
        if other == name:
            continue
        warm = state.warm.get(other)
        if warm is None:
            others.append(np.repeat(yhat[None], horizon, axis=0))
        else:
            others.append(np.vstack([warm[1:], warm[-1:]]))
    return np.array(others)


REJECTED = "REJECTED_DIVERGED"
STRAY_M = 10.0  # an estimate this far outside the workspace is not planned by the MPC
DIVERGED_STEPS = 5.0  # a plan's step this many times the reach is a solve gone wrong


def _near_workspace(position: np.ndarray, context: RunContext) -> bool:
    box = context.scenario.world.workspace
    low, high = np.array(box.min_m) - STRAY_M, np.array(box.max_m) + STRAY_M
    return bool(np.all(np.isfinite(position)) and np.all((position >= low) & (position <= high)))


def _plausible(path: np.ndarray, yhat: np.ndarray, reach: float) -> bool:
    """A plan that is finite and whose steps are not many times what the support can fly."""
    if not np.all(np.isfinite(path)):
        return False
    steps = np.linalg.norm(np.diff(np.vstack([yhat, path]), axis=0), axis=1)
    return bool(np.all(steps <= DIVERGED_STEPS * reach))


def _held(plan: SupportPlan, yhat: np.ndarray) -> SupportPlan:
    path = np.repeat(np.asarray(yhat, dtype=float)[None], len(plan.path), axis=0)
    return SupportPlan(path, REJECTED, plan.solve_ms, plan.blocked, False, plan.anchors)


def _straight_back(state: StationState, name: str, context: RunContext, reach: float):
    """A support far outside the workspace flies straight toward its current waypoint."""
    yhat = state.yhat[name]
    target = context.support_waypoints[name][min(state.k, len(context.support_waypoints[name]) - 1)]
    horizon = context.scenario.control.horizon_steps
    direction = target - yhat
    distance = float(np.linalg.norm(direction))
    steps = np.arange(1, horizon + 1)[:, None] * reach
    path = yhat + direction / max(distance, 1e-9) * np.minimum(steps, distance)
    none = np.zeros(0)
    return SupportPlan(path, "OUTSIDE_WORKSPACE", 0.0, np.zeros(horizon, dtype=bool), False, none)
