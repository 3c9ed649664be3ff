"""What dynamic roles cost the control cycle: a detached Piers AC run with the
dynamic policy (the work UAV's own fix judged, the look-ahead, releases, recalls and routes)
against the paper's cycle (fixed roles, no inspections: nothing of the roles runs), on the
same waypoints, stepped in turn cycle by cycle (:mod:`mission.bench.paired`). Piers' first
cycles fly the open sky, release supports and recall them."""

from __future__ import annotations

from mission.bench.result import BenchResult

TARGET = 1.10  # the cycle's median may grow by a tenth


def bench_roles(cycles: int = 240, repeats: int = 3) -> list[BenchResult]:
    """The median cycle time with dynamic roles over fixed (target: the median of the ratios
    of ``repeats`` pairs of runs), and the longest dynamic cycle (a route's search;
    reference)."""
    from mission.bench.paired import paired_cycle_ratio
    from mission.config.scenario import load_scenario
    from mission.world.model import World

    worlds = {
        "fixed": World(load_scenario("piers", {"task.inspections": []})),
        "dynamic": World(load_scenario("piers", {"roles.policy": "dynamic"})),
    }
    ratio, longest = paired_cycle_ratio(worlds, cycles, repeats)
    return [
        BenchResult("dynamic_roles_cycle_ratio", ratio, "x", f"<= {TARGET:g}", ratio <= TARGET),
        BenchResult("dynamic_roles_cycle_ms_max", longest, "ms", "reference", None),
    ]
