"""The floor under a run's CPU seconds: the same Along AC mission decided in one process.

A detached run (:mod:`mission.bench.detached`) decides as a run does - the ground station's
five steps and the three support MPCs each cycle, the same code - against in-process
kinematic vehicles that sense as the vehicle processes do (its own noise streams, no receiver
lag, no sensor failures), with no MAVLink, no sockets and no other processes. Its CPU seconds
estimate what a run's decisions cost on this machine; ``run_cpu_s`` (all of a run's
processes) sits on top of them.

A run's CPU seconds over these (``run_over_detached_cpu_ratio``, where one invocation reads
both) say what the processes, MAVLink, start-up and analysis add to the decisions.
"""

from __future__ import annotations

import statistics
import time

from mission.bench.result import BenchResult


def bench_floor(repeats: int = 3, max_cycles: int = 1000) -> list[BenchResult]:
    """CPU seconds of a detached Along AC run to completion and the time its support MPCs'
    plans took (their wall-clock sum: in one process, mostly CPU); medians of ``repeats``
    (references)."""
    from mission.bench.detached import run_detached
    from mission.link.plan_files import read_plan
    from mission.world.model import World

    world = World.load("along")
    plan = read_plan(world.scenario)
    waypoints = {"work": plan.work, **{f"support-{n + 1}": p for n, p in enumerate(plan.supports)}}
    totals, plans = [], []
    for _ in range(repeats):
        start = time.process_time()
        run = run_detached(world, waypoints, adaptive=True, seed=0, max_cycles=max_cycles)
        totals.append(time.process_time() - start)
        if not run.completed:
            raise RuntimeError(f"the detached Along AC run did not finish in {max_cycles} cycles")
        solves_ms = [p.solve_ms for o in run.outputs for p in o.support_plans.values()]
        plans.append(sum(solves_ms) / 1000)
    return [
        BenchResult("detached_run_cpu_s", statistics.median(totals), "s", "reference", None),
        BenchResult("detached_plans_s", statistics.median(plans), "s", "reference", None),
    ]
