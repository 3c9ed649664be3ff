"""What the safety margins cost the support MPC: the same problems (every support MPC posed in
a detached Along run in the paper's form) solved with and without the margins, alternately in
one process, so both see the same machine."""

from __future__ import annotations

import statistics
import time

from mission.runs.bench_result import BenchResult

TARGET = 1.25  # the margins may cost at most a quarter more, median and p95


def bench_margins(cycles: int = 200) -> list[BenchResult]:
    """Median and p95 solve time with the default margins over without, on identical
    problems."""
    import numpy as np

    from ground_station import support_planning
    from ground_station.support_mpc import SupportMpc
    from mission.config.scenario import load_scenario
    from mission.link.plan_files import read_plan
    from mission.runs.detached import run_detached
    from mission.world.model import World

    paper = World(load_scenario("along", {"control.min_separation_m": 0, "control.clearance_m": 0}))
    safe = load_scenario("along")
    plan = read_plan(paper.scenario)
    waypoints = {"work": plan.work, **{f"support-{n + 1}": s for n, s in enumerate(plan.supports)}}
    requests = []
    recording = support_planning.LocalPlanner.plan_all

    def record(planner, batch):
        requests.extend(batch)
        return recording(planner, batch)

    support_planning.LocalPlanner.plan_all = record
    try:
        run_detached(paper, waypoints, adaptive=True, seed=0, max_cycles=cycles)
    finally:
        support_planning.LocalPlanner.plan_all = recording
    sigma0, grid, camera = paper.sigma0_map().sigma_m, paper.map_grid(), paper.camera
    others = safe.task.supports
    without = SupportMpc(paper.scenario.control, grid, camera, sigma0, others=others)
    with_margins = SupportMpc(safe.control, grid, camera, sigma0, others=others)
    times: dict[str, list[float]] = {"without": [], "with": []}
    for request in requests:
        for label, mpc in (("without", without), ("with", with_margins)):
            start = time.perf_counter()
            mpc.plan(request, camera.observable)
            times[label].append(time.perf_counter() - start)
    median = statistics.median(times["with"]) / statistics.median(times["without"])
    p95 = float(np.percentile(times["with"], 95) / np.percentile(times["without"], 95))
    target = f"<= {TARGET:g}"
    return [
        BenchResult("support_mpc_margins_median_ratio", median, "x", target, median <= TARGET),
        BenchResult("support_mpc_margins_p95_ratio", p95, "x", target, p95 <= TARGET),
    ]
