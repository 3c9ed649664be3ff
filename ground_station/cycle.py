"""The control cycle of the paper's Section 4, one call per t_cont:

1. localize (GNSS and relative observations, already typed),
2. fuse (selective fusion for the work UAV, feedback to each support),
3. check arrival at the current work waypoint,
4. update the GNSS-localizability map G (AC only),
5. predict with the MPCs and command the first step.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ground_station.fusion import (
    FusionResult,
    SupportMeasurement,
    selective_fusion,
    support_feedback,
)
from ground_station.localizability import LocalizabilityMap, hermite_zero_slope
from ground_station.support_mpc import PlanRequest, SupportMpc, SupportPlan
from ground_station.support_planning import LocalPlanner
from ground_station.work_mpc import WorkPrediction, predict_work
from mission.config.settings import Scenario
from mission.world.model import World

ESCAPE_MARGIN_M = 0.25  # G_s this far above its start at yhat: try escape starts too


@dataclass
class Models:
    """What the ground station knows and computes with, built once per run."""

    scenario: Scenario
    world: World
    work_waypoints: np.ndarray
    support_waypoints: dict[str, np.ndarray]
    g: LocalizabilityMap
    support_mpc: SupportMpc
    rng: np.random.Generator
    planner: LocalPlanner  # solves the support MPCs: here, or shared with a helper process


@dataclass
class StationState:
    """Estimates and progress carried from one cycle to the next."""

    xhat: np.ndarray
    yhat: dict[str, np.ndarray]
    k: int
    last_work_command: np.ndarray = field(default_factory=lambda: np.zeros(3))
    last_support_command: dict[str, np.ndarray] = field(default_factory=dict)
    warm: dict[str, np.ndarray] = field(default_factory=dict)
    betas: dict[str, float | None] = field(default_factory=dict)
    completed: bool = False


@dataclass(frozen=True)
class CycleOutput:
    """Commands and everything worth recording about one cycle."""

    work_target: np.ndarray
    support_targets: dict[str, np.ndarray]
    fusion: FusionResult
    betas: dict[str, float | None]
    arrived: int | None
    updated_voxels: int
    work_prediction: WorkPrediction
    support_plans: dict[str, SupportPlan]
    cycle_ms: float


def control_cycle(
    state: StationState,
    supports: list[SupportMeasurement],
    models: Models,
    work_ready: Callable[[np.ndarray, int | None], None] | None = None,
) -> CycleOutput:
    """One control cycle; updates ``state`` in place and returns the commands.

    ``work_ready(command, reached)`` is called as soon as the work UAV's command (and the
    waypoint it reached, if any) is known, before the support MPCs are solved: the ground
    station sends it at once, and the work vehicle steps while they are solved.
    """
    start = time.perf_counter()
    control = models.scenario.control
    fusion = fuse(state, supports, models)  # steps 1-2
    arrived = check_arrival(state, models.work_waypoints, control.arrival_tol_m)  # step 3
    updated = sum(
        models.g.update(s.fix_m, state.yhat[s.name])  # step 4
        for s in supports
        if s.fix_m is not None and s.relative_m is not None
    )
    work = predict_work(
        state.xhat,
        state.k,
        models.work_waypoints,  # step 5
        control.horizon_steps,
        control.d_max_work_m,
        control.arrival_tol_m,
    )
    if work_ready is not None:
        work_ready(work.command, arrived)
    plans = models.planner.plan_all(
        [s.name for s in supports], lambda name: support_request(state, name, work, models)
    )
    state.last_work_command = _reachable(
        state.xhat, work.command, control.s_max_work_m_s * control.t_cont_s
    )
    for name, plan in plans.items():
        state.last_support_command[name] = _reachable(
            state.yhat[name], plan.command, control.s_max_support_m_s * control.t_cont_s
        )
        state.warm[name] = plan.path
    return CycleOutput(
        work.command,
        {n: p.command for n, p in plans.items()},
        fusion,
        dict(state.betas),
        arrived,
        updated,
        work,
        plans,
        (time.perf_counter() - start) * 1000,
    )


def fuse(state: StationState, supports: list[SupportMeasurement], models: Models) -> FusionResult:
    """Selective fusion for xhat, then feedback to every support's yhat."""
    predicted = state.xhat + state.last_work_command
    fusion = selective_fusion(supports, predicted, models.scenario.fusion, models.rng)
    if fusion.xhat is not None:
        state.xhat = fusion.xhat
    state.betas = {}
    for support in supports:
        previous = state.yhat[support.name]
        moved = state.last_support_command.get(support.name, np.zeros(3))
        result = support_feedback(support, fusion, previous, moved)
        state.yhat[support.name] = result.yhat
        state.betas[support.name] = result.beta
    return fusion


def check_arrival(state: StationState, waypoints: np.ndarray, tolerance_m: float) -> int | None:
    """Advance k_now when |w_k - xhat| < tolerance; return the index reached, if any."""
    if np.linalg.norm(waypoints[state.k] - state.xhat) >= tolerance_m:
        return None
    reached = state.k
    if state.k == len(waypoints) - 1:
        state.completed = True
    else:
        state.k += 1
    return reached


def support_request(
    state: StationState, name: str, work: WorkPrediction, models: Models
) -> PlanRequest:
    """The support MPC's problem for one support; escape starts where G says GNSS is worse
    than expected."""
    yhat = state.yhat[name]
    g = models.g
    escape = bool(g.smoothed(yhat)[0] > _initial_smoothed(g, yhat) + ESCAPE_MARGIN_M)
    return models.support_mpc.request(
        name,
        yhat,
        models.support_waypoints[name],
        work.path,
        work.indices,
        g.values,
        state.warm.get(name),
        escape=escape,
    )


def _initial_smoothed(g: LocalizabilityMap, point: np.ndarray) -> float:
    return float(hermite_zero_slope(g.initial, g.grid, point)[0])


def _reachable(start: np.ndarray, target: np.ndarray, reach: float) -> np.ndarray:
    """The displacement a vehicle makes toward ``target`` in one cycle."""
    move = target - start
    distance = float(np.linalg.norm(move))
    return move if distance <= reach else move * (reach / distance)
