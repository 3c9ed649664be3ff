"""The floor under a run's CPU seconds: the same Along AC mission decided in one process.

A detached run (:mod:`mission.bench.detached`) decides as a run does - the ground station's
five steps and the three support MPCs each cycle, the same code - against in-process
kinematic vehicles that sense as the vehicle processes do (its own noise streams, no receiver
lag, no sensor failures), with no MAVLink, no sockets and no other processes. Its CPU seconds
estimate what a run's decisions cost on this machine; ``run_cpu_s`` (all of a run's
processes) sits on top of them.

The machine's speed is read just before each detached run (a shared VM's drifts by tens of
per cent within minutes), and the run's CPU seconds are set against ``run_cpu_s``'s target at
that speed: above 1, the target is below what the decisions alone cost.
"""

from __future__ import annotations

import statistics
import time

from mission.bench.result import BenchResult

RUN_CPU_TARGET_S = 3.5  # CPU seconds of a whole Along AC run at the reference speed


def bench_floor(repeats: int = 3, max_cycles: int = 1000) -> list[BenchResult]:
    """CPU seconds of a detached Along AC run to completion, the time its support MPCs' plans
    took (their wall-clock sum: in one process, mostly CPU), and the run's CPU over
    ``run_cpu_s``'s target (medians of ``repeats``; references)."""
    from mission.bench.detached import run_detached
    from mission.link.plan_files import read_plan
    from mission.procs.machine_speed import REFERENCE_LOOP_S, python_loop_s
    from mission.world.model import World

    world = World.load("along")
    plan = read_plan(world.scenario)
    waypoints = {"work": plan.work, **{f"support-{n + 1}": p for n, p in enumerate(plan.supports)}}
    totals, plans, over_target = [], [], []
    for _ in range(repeats):
        target_s = RUN_CPU_TARGET_S * python_loop_s(3) / REFERENCE_LOOP_S
        start = time.process_time()
        run = run_detached(world, waypoints, adaptive=True, seed=0, max_cycles=max_cycles)
        totals.append(time.process_time() - start)
        if not run.completed:
            raise RuntimeError(f"the detached Along AC run did not finish in {max_cycles} cycles")
        solves_ms = [p.solve_ms for o in run.outputs for p in o.support_plans.values()]
        plans.append(sum(solves_ms) / 1000)
        over_target.append(totals[-1] / target_s)
    return [
        BenchResult("detached_run_cpu_s", statistics.median(totals), "s", "reference", None),
        BenchResult("detached_plans_s", statistics.median(plans), "s", "reference", None),
        BenchResult(
            "detached_run_cpu_over_run_target",
            statistics.median(over_target),
            "x",
            "reference",
            None,
        ),
    ]
