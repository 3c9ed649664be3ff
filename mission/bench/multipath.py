"""What multipath from geometry costs a run: the same flight's GNSS fixes made by
both models.

A run with ``geometry`` flies differently from one with ``zones`` (other errors, other
decisions), so two whole runs would compare two flights. Instead one lockstep run of the
river mission with ``multipath: zones`` is made as a user makes it (all its processes' CPU
seconds), and every fix its four vehicles took is made again in this process at the same true
positions by a zones world and by a geometry world, in turn, block by block. The geometry run's
CPU is the run's plus the difference: everything else in a run (decisions, links, the other
sensors) is the same by construction.
"""

from __future__ import annotations

import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from mission.bench.result import BenchResult

TARGET = 1.15  # a run with geometry costs at most this times a zones run's CPU
ZONES_RIVER = "extends: river\nname: river-zones\nworld: {gnss: {multipath: zones}}\n"
BLOCK = 50  # fixes timed in a row before the other model's turn


def bench_multipath(repeats: int = 3) -> list[BenchResult]:
    """The geometry run's CPU over the zones run's (median of ``repeats`` timings of the same
    fixes) and the geometry model's cost per fix (a reference)."""
    from mission.analysis.metrics import read_tlog
    from mission.bench.run_command import run_as_command
    from mission.config.scenario import load_scenario
    from mission.procs.machine_speed import children_cpu_s
    from mission.world.model import World

    with tempfile.TemporaryDirectory(prefix="bench-multipath-") as temp:
        scenario_file = Path(temp) / "river-zones.yaml"
        scenario_file.write_text(ZONES_RIVER)
        before = children_cpu_s()
        run_as_command(str(scenario_file), "ac", Path(temp) / "run")
        run_cpu = children_cpu_s() - before
        zones_scenario = load_scenario(str(scenario_file))
        trace = read_tlog(Path(temp) / "run" / "gcs.tlog", zones_scenario)
    positions = _fix_positions(trace)
    worlds = {"zones": World(zones_scenario), "geometry": World(load_scenario("river"))}
    added, per_fix = [], []
    for repeat in range(repeats):
        spent = _time_fixes(worlds, positions, first="zones" if repeat % 2 == 0 else "geometry")
        added.append(spent["geometry"] - spent["zones"])
        per_fix.append(spent["geometry"] / len(positions) * 1e6)
    ratio = (run_cpu + statistics.median(added)) / run_cpu
    return [
        BenchResult("multipath_run_cpu_ratio", ratio, "x", f"<= {TARGET:g}", ratio <= TARGET),
        BenchResult("multipath_fix_us", statistics.median(per_fix), "us", "reference", None),
    ]


def _fix_positions(trace) -> np.ndarray:
    """The true position of every vehicle at every fix it reported."""
    from mission.analysis.gnss_errors import fixes_and_truth

    systems = sorted({s for s, _ in trace.fixes})
    return np.vstack([fixes_and_truth(trace, system)[1] for system in systems])


def _time_fixes(worlds: dict, positions: np.ndarray, first: str) -> dict[str, float]:
    """CPU seconds each world spends on the fixes at ``positions``, in turn by blocks."""
    order = [first, *(name for name in worlds if name != first)]
    spent = dict.fromkeys(worlds, 0.0)
    rngs = {name: np.random.default_rng(0) for name in worlds}
    for start in range(0, len(positions), BLOCK):
        block = positions[start : start + BLOCK]
        for name in order:
            world, rng = worlds[name], rngs[name]
            begin = time.process_time()
            for point in block:
                world.gnss_fix(point, rng)
            spent[name] += time.process_time() - begin
    return spent
