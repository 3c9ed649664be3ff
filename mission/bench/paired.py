"""Two detached runs of one scenario in two settings stepped in turn, cycle by cycle, in one
process: what a setting costs the control cycle, each run seeing the machine's slow spells
alike (a whole run's median varies by a third between runs on one machine; run one after the
other, a ratio of two medians read from 0.74 to 1.15)."""

from __future__ import annotations

import statistics
from typing import Any


def paired_cycle_ratio(worlds: dict[str, Any], cycles: int, repeats: int) -> tuple[float, float]:
    """(the median over ``repeats`` pairs of runs of the second setting's median cycle time
    over the first's, the second's longest cycle in ms); ``worlds``: two settings' worlds, the
    reference first, on the first's planned waypoints; each setting first in turn."""
    from mission.bench.detached import detached_cycles
    from mission.link.plan_files import read_plan

    reference, other = list(worlds)
    plan = read_plan(worlds[reference].scenario)
    waypoints = {"work": plan.work, **{f"support-{n + 1}": p for n, p in enumerate(plan.supports)}}
    ratios, longest = [], 0.0
    for repeat in range(repeats):
        times: dict[str, list[float]] = {reference: [], other: []}
        order = [reference, other] if repeat % 2 == 0 else [other, reference]
        runs = {
            name: detached_cycles(worlds[name], waypoints, adaptive=True, seed=0, max_cycles=cycles)
            for name in order
        }
        while runs:
            for name in list(runs):
                cycle = next(runs[name], None)
                if cycle is None:
                    del runs[name]
                else:
                    times[name].append(cycle[0].cycle_ms)
        ratios.append(statistics.median(times[other]) / statistics.median(times[reference]))
        longest = max(longest, max(times[other]))
    return statistics.median(ratios), longest
