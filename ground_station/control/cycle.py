"""The control cycle of the paper's Section 4, run every t_cont: five steps, one call each.

1. localize: each support's GNSS fix p_n and camera observation r_n (brought to the cycle's
   time, :mod:`~ground_station.estimation.align`), with covariances;
2. fuse: selective fusion for the work UAV's xhat, feedback for each support's yhat_n; with
   ``roles.policy: dynamic`` the work UAV's own GNSS fix judged and, trusted, fused too
   (:mod:`~ground_station.roles.own_fix`);
3. check arrival at the current work waypoint (|w_k - xhat| < 0.1 m advances k; not when
   blind);
4. learn: G updated around each yhat_n with the GNSS error seen there (AC only); then, where
   the supports have inspections of their own, who is in the formation and who inspects
   (:mod:`~ground_station.roles.allocation`);
5. plan: the work UAV's path (Algorithm 1; blind, it holds), then each formation support's MPC
   around it (a support off the formation flies its route).

:func:`control_cycle` runs the five steps up to the work UAV's plan; :func:`complete_cycle`
then poses and solves the supports' MPCs. The ground station sends the work UAV its command
between the two: that command does not depend on the supports' plans, and the work vehicle
steps while they are solved.
:func:`run_cycle` does both for callers that send nothing in between.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from ground_station.control.arrival import check_arrival
from ground_station.control.plan import FormationPlan, plan, solve_supports
from ground_station.control.run_context import RunContext
from ground_station.control.work_mpc import WorkPrediction
from ground_station.estimation.align import align
from ground_station.estimation.fusion import FusionResult, SupportMeasurement, fuse
from ground_station.estimation.gnss_map import learn
from ground_station.estimation.localize import SupportReport, localize
from ground_station.integrity.monitor import Verdict
from ground_station.roles.allocation import allocate
from ground_station.roles.own_fix import OwnFix, combined_estimate, judge
from ground_station.state.station_state import StationState
from ground_station.support_mpc.mpc import SupportPlan


@dataclass(frozen=True)
class CycleDecision:
    """The five steps' results: the work UAV's command is known, the supports' MPCs not yet
    solved."""

    measurements: list[SupportMeasurement]
    fusion: FusionResult
    betas: dict[str, float | None]
    arrived: int | None
    updated_voxels: int
    formation: FormationPlan
    elapsed_ms: float
    own_fix: OwnFix | None = None  # the verdict on the work UAV's own fix (policy dynamic)
    integrity: Verdict | None = None  # the integrity monitor's, where it is on

    @property
    def blind(self) -> bool:
        """No estimate of the work UAV this cycle."""
        return is_blind(self.fusion, self.own_fix)

    @property
    def work_command(self) -> np.ndarray:
        """The work UAV's position target: the first point of its predicted path."""
        return self.formation.work.command


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
    own_fix: OwnFix | None = None
    integrity: Verdict | None = None

    @property
    def blind(self) -> bool:
        """No estimate of the work UAV this cycle."""
        return is_blind(self.fusion, self.own_fix)


def is_blind(fusion: FusionResult, own_fix: OwnFix | None) -> bool:
    """No support contributed and the work UAV's own fix was not used."""
    return fusion.blind and not (own_fix is not None and own_fix.used)


def control_cycle(
    state: StationState,
    reports: Sequence[SupportReport],
    context: RunContext,
    work_fix: np.ndarray | None = None,
) -> CycleDecision:
    """The paper's five steps for this cycle's reports (and the work UAV's own 3-D fix, ENU,
    where it has one); updates ``state`` in place."""
    start = time.perf_counter()
    control, roles = context.scenario.control, context.scenario.roles
    measurements = localize(align(reports, state, control.t_cont_s), context.world)  # 1
    fusion, betas, verdict, fused = _checked_fusion(state, measurements, context)  # 2
    own = None
    if roles.policy == "dynamic":
        own = judge(work_fix, fusion, context.g, context.world, roles)
        if own.used:
            assert work_fix is not None
            state.xhat = combined_estimate(work_fix, own, fusion)
    blind = is_blind(fusion, own)  # then no waypoint is reached
    arrived = None if blind else check_arrival(state, context.work_waypoints, control.arrival_tol_m)
    updated = learn(context.g, fused, state.yhat)  # 4
    if verdict is not None and context.integrity is not None:
        updated += context.integrity.learn_excluded(
            context.g, measurements, state.yhat, verdict.events
        )
    allocate(state, context, state.allocation)
    members = state.allocation.members([m.name for m in measurements])
    formation = plan(state, context, members, hold=blind)  # 5
    elapsed_ms = (time.perf_counter() - start) * 1000
    return CycleDecision(
        measurements, fusion, betas, arrived, updated, formation, elapsed_ms, own, verdict
    )


def _checked_fusion(
    state: StationState, measurements: list[SupportMeasurement], context: RunContext
) -> tuple[FusionResult, dict[str, float | None], Verdict | None, list[SupportMeasurement]]:
    """Step 2, with the integrity monitor's tests between localize and fuse where it is on:
    a withheld support's fix is neither fused nor taken into its estimate. Returns the
    fusion, each support's beta_n, the monitor's verdict (None: off) and the measurements as
    fused."""
    settings, monitor = context.scenario.fusion, context.integrity
    if monitor is None:
        return *fuse(state, measurements, settings, context.rng), None, measurements
    verdict = monitor.check(measurements, state)
    fused = [withheld(m) if m.name in verdict.withheld else m for m in measurements]
    fusion, betas = fuse(state, fused, settings, context.rng)
    return fusion, betas, monitor.settle(measurements, state, fusion, verdict), fused


def withheld(measurement: SupportMeasurement) -> SupportMeasurement:
    """A support's measurement without its fix: not fused, dead-reckoned by the feedback."""
    return replace(measurement, fix_m=None, sigma_gnss_m2=None)


def complete_cycle(
    state: StationState, decision: CycleDecision, context: RunContext
) -> CycleOutput:
    """The supports' MPCs solved: the cycle's commands and record."""
    start = time.perf_counter()
    plans = solve_supports(state, decision.formation, context)
    return CycleOutput(
        decision.work_command,
        {name: support_plan.command for name, support_plan in plans.items()},
        decision.fusion,
        decision.betas,
        decision.arrived,
        decision.updated_voxels,
        decision.formation.work,
        plans,
        decision.elapsed_ms + (time.perf_counter() - start) * 1000,
        decision.own_fix,
        decision.integrity,
    )


def run_cycle(
    state: StationState,
    reports: Sequence[SupportReport],
    context: RunContext,
    work_fix: np.ndarray | None = None,
) -> CycleOutput:
    """A whole cycle with nothing sent in between (the detached run of
    :mod:`mission.bench.detached`, tests)."""
    return complete_cycle(state, control_cycle(state, reports, context, work_fix), context)
