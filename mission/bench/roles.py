"""What dynamic roles (issue 33) cost the control cycle: a detached Piers AC run with the
dynamic policy (the work UAV's own fix judged, the look-ahead, releases, recalls and routes)
against the paper's cycle (fixed roles, no inspections: nothing of the roles runs), on the
same waypoints, stepped in turn cycle by cycle in one process so that both see the machine's
slow spells alike (a whole run's median varies by a third between runs on one machine; run
one after the other, the ratio read from 0.74 to 1.15). Piers' first cycles fly the open
sky, release supports and recall them."""

from __future__ import annotations

import statistics

from mission.bench.result import BenchResult

TARGET = 1.10  # the cycle's median may grow by a tenth


def bench_roles(cycles: int = 240, repeats: int = 3) -> list[BenchResult]:
    """The median cycle time with dynamic roles over fixed (target: the median of the ratios
    of ``repeats`` pairs of runs), and the longest dynamic cycle (a route's search;
    reference)."""
    from mission.bench.detached import detached_cycles
    from mission.config.scenario import load_scenario
    from mission.link.plan_files import read_plan
    from mission.world.model import World

    worlds = {
        "fixed": World(load_scenario("piers", {"task.inspections": []})),
        "dynamic": World(load_scenario("piers", {"roles.policy": "dynamic"})),
    }
    plan = read_plan(worlds["fixed"].scenario)
    waypoints = {"work": plan.work, **{f"support-{n + 1}": p for n, p in enumerate(plan.supports)}}
    ratios, longest = [], 0.0
    for repeat in range(repeats):
        times: dict[str, list[float]] = {"fixed": [], "dynamic": []}
        order = list(worlds) if repeat % 2 == 0 else list(worlds)[::-1]  # each first in turn
        runs = {
            policy: detached_cycles(
                worlds[policy], waypoints, adaptive=True, seed=0, max_cycles=cycles
            )
            for policy in order
        }
        while runs:
            for policy in list(runs):
                cycle = next(runs[policy], None)
                if cycle is None:
                    del runs[policy]
                else:
                    times[policy].append(cycle[0].cycle_ms)
        ratios.append(statistics.median(times["dynamic"]) / statistics.median(times["fixed"]))
        longest = max(longest, max(times["dynamic"]))
    ratio = statistics.median(ratios)
    return [
        BenchResult("dynamic_roles_cycle_ratio", ratio, "x", f"<= {TARGET:g}", ratio <= TARGET),
        BenchResult("dynamic_roles_cycle_ms_max", longest, "ms", "reference", None),
    ]
