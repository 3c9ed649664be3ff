"""What the integrity monitor costs the control cycle: a detached Along AC run with
``integrity.enabled`` against one without, stepped in turn cycle by cycle
(:mod:`mission.bench.paired`). Along's support 1 crosses the zone, so the monitor excludes,
places by the formation and restores, as well as testing every fix."""

from __future__ import annotations

from mission.bench.result import BenchResult

TARGET = 1.05  # the cycle's median may grow by a twentieth


def bench_integrity(cycles: int = 240, repeats: int = 3) -> list[BenchResult]:
    """The median cycle time with the monitor over without (target: the median of the ratios
    of ``repeats`` pairs of runs)."""
    from mission.bench.paired import paired_cycle_ratio
    from mission.config.scenario import load_scenario
    from mission.world.model import World

    worlds = {
        "off": World(load_scenario("along")),
        "on": World(load_scenario("along", {"integrity.enabled": True})),
    }
    ratio, _ = paired_cycle_ratio(worlds, cycles, repeats)
    return [BenchResult("integrity_cycle_ratio", ratio, "x", f"<= {TARGET:g}", ratio <= TARGET)]
