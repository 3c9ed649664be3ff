"""The control cycle against in-process vehicles: no sockets, no MAVLink.

The vehicles here move exactly as :mod:`vehicle_sim` moves them (same kinematics, same sensor
context), so the ground station's algorithms can be timed and studied without processes, as
BlueSky's detached node runs a simulation without a network. Used by the benchmarks.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from ground_station.control.cycle import CycleOutput, run_cycle
from ground_station.control.run_context import build_run_context
from ground_station.estimation.localize import SupportReport
from ground_station.roles.allocation import inspections_left
from mission.world.model import World
from vehicle_sim.dynamics.kinematics import Kinematics


@dataclass(frozen=True)
class DetachedRun:
    """Outputs of every cycle, the true positions, and whether the work UAV finished."""

    outputs: list[CycleOutput]
    work_truth: np.ndarray
    completed: bool


def run_detached(
    world: World,
    waypoints: dict[str, np.ndarray],
    adaptive: bool,
    seed: int,
    max_cycles: int,
) -> DetachedRun:
    """Run up to ``max_cycles`` control cycles (or to completion)."""
    outputs, truth, completed = [], [], False
    for output, work_truth, done in detached_cycles(world, waypoints, adaptive, seed, max_cycles):
        outputs.append(output)
        truth.append(work_truth)
        completed = done
    return DetachedRun(outputs, np.array(truth), completed)


def detached_cycles(
    world: World,
    waypoints: dict[str, np.ndarray],
    adaptive: bool,
    seed: int,
    max_cycles: int,
) -> Iterator[tuple[CycleOutput, np.ndarray, bool]]:
    """Each cycle as it is run: its output, the work UAV's true position when it began, and
    whether the work UAV's task is complete (two runs can be stepped in turn)."""
    scenario = world.scenario
    control = scenario.control
    context, state = build_run_context(world.known(), waypoints, adaptive, seed)
    rng = np.random.default_rng([seed, 99])
    own_rng = np.random.default_rng([seed, 98])  # the work UAV's own fixes (dynamic roles)
    vehicles = {name: Kinematics.at(points[0]) for name, points in waypoints.items()}
    speed = {
        name: control.s_max_work_m_s if name == "work" else control.s_max_support_m_s
        for name in waypoints
    }
    for _ in range(max_cycles):
        work_truth = vehicles["work"].truth
        reports = []
        for name in context.support_waypoints:
            y = vehicles[name].truth
            fix = world.gnss_fix(y, rng)
            observation = world.camera.observe(y, work_truth, rng)
            position = fix.position_m if fix.has_fix else None
            reports.append(SupportReport(name, position, observation.relative_m))
        work_fix = None
        if scenario.roles.policy == "dynamic":
            fix = world.gnss_fix(work_truth, own_rng)
            work_fix = fix.position_m if fix.has_fix else None
        output = run_cycle(state, reports, context, work_fix)
        yield output, work_truth.copy(), state.completed
        if not output.blind:  # blind, the work UAV holds on its own dead reckoning
            vehicles["work"].set_estimate(state.xhat)
        vehicles["work"].target = output.work_target
        for name, target in output.support_targets.items():
            vehicles[name].set_estimate(state.yhat[name])
            vehicles[name].target = target
        for name, vehicle in vehicles.items():
            vehicle.step(control.t_cont_s, speed[name], rng, scenario.vehicle.tracking_noise_m)
        if state.completed and not inspections_left(state.allocation, context):
            break
