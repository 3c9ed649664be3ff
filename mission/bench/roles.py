"""What dynamic roles (issue 33) cost the control cycle: a detached Piers AC run with the
dynamic policy (the work UAV's own fix judged, the look-ahead, releases, recalls and routes)
against the paper's cycle (fixed roles, no inspections: nothing of the roles runs), on the
same waypoints, alternately in one process, so both see the same machine. Piers' first
cycles fly the open sky, release supports and recall them."""

from __future__ import annotations

import statistics

from mission.bench.result import BenchResult

TARGET = 1.10  # the cycle's median may grow by a tenth


def bench_roles(cycles: int = 240, repeats: int = 3) -> list[BenchResult]:
    """The median cycle time with dynamic roles over fixed (target), and the longest dynamic
    cycle (a route's search; reference)."""
    from mission.bench.detached import run_detached
    from mission.config.scenario import load_scenario
    from mission.link.plan_files import read_plan
    from mission.world.model import World

    worlds = {
        "fixed": World(load_scenario("piers", {"task.inspections": []})),
        "dynamic": World(load_scenario("piers", {"roles.policy": "dynamic"})),
    }
    plan = read_plan(worlds["fixed"].scenario)
    waypoints = {"work": plan.work, **{f"support-{n + 1}": p for n, p in enumerate(plan.supports)}}
    medians: dict[str, list[float]] = {"fixed": [], "dynamic": []}
    longest = 0.0
    for _ in range(repeats):
        for policy, world in worlds.items():
            run = run_detached(world, waypoints, adaptive=True, seed=0, max_cycles=cycles)
            times = [o.cycle_ms for o in run.outputs]
            medians[policy].append(statistics.median(times))
            if policy == "dynamic":
                longest = max(longest, max(times))
    ratio = statistics.median(medians["dynamic"]) / statistics.median(medians["fixed"])
    return [
        BenchResult("dynamic_roles_cycle_ratio", ratio, "x", f"<= {TARGET:g}", ratio <= TARGET),
        BenchResult("dynamic_roles_cycle_ms_max", longest, "ms", "reference", None),
    ]
