"""What the safety margins cost the support MPC: the same problems solved with and without the
margins, alternately in one process, so both see the same machine.

The problems are every support MPC posed in a detached Along AC run with the defaults: the
problems the margins meet in use. A run in the paper's form poses others (its supports fly
inside each other's margins and the deck's, so most of its problems cannot keep them and
the exact penalty works hard): their ratios are given as a reference."""

from __future__ import annotations

import statistics
import time

from mission.bench.result import BenchResult

TARGET = 1.25  # the margins may cost at most a quarter more, median and p95
PAPER_FORM = {"control.min_separation_m": 0, "control.clearance_m": 0}


def bench_margins(cycles: int = 200) -> list[BenchResult]:
    """Median and p95 solve time with the default margins over without, on identical
    problems: those of a run with the margins (target), and of one without (reference)."""
    from mission.config.scenario import load_scenario
    from mission.world.model import World

    paper, safe = World(load_scenario("along", PAPER_FORM)), World(load_scenario("along"))
    results = []
    for label, source, target in (("", safe, True), ("_paper_run", paper, False)):
        median, p95 = _ratios(_posed(source, cycles), paper, safe)
        for name, value in (("median", median), ("p95", p95)):
            ok = value <= TARGET if target else None
            results.append(
                BenchResult(
                    f"support_mpc_margins_{name}_ratio{label}",
                    value,
                    "x",
                    f"<= {TARGET:g}" if target else "reference",
                    ok,
                )
            )
    return results


def _posed(world, cycles: int) -> list:
    """Every support MPC problem posed in the first ``cycles`` of a detached Along AC run."""
    from ground_station.support_mpc import sharing
    from mission.bench.detached import run_detached
    from mission.link.plan_files import read_plan

    plan = read_plan(world.scenario)
    waypoints = {"work": plan.work, **{f"support-{n + 1}": s for n, s in enumerate(plan.supports)}}
    requests = []
    recording = sharing.LocalPlanner.plan_all

    def record(planner, batch):
        requests.extend(batch)
        return recording(planner, batch)

    sharing.LocalPlanner.plan_all = record
    try:
        run_detached(world, waypoints, adaptive=True, seed=0, max_cycles=cycles)
    finally:
        sharing.LocalPlanner.plan_all = recording
    return requests


def _ratios(requests: list, paper, safe) -> tuple[float, float]:
    """(median, p95) of the solve time with the margins over without, on ``requests``."""
    import numpy as np

    from ground_station.support_mpc.mpc import SupportMpc

    sigma0, grid, camera = paper.sigma0_map().sigma_m, paper.map_grid(), paper.camera
    others = safe.scenario.task.supports
    without = SupportMpc(paper.scenario.control, grid, camera, sigma0, others=others)
    with_margins = SupportMpc(safe.scenario.control, grid, camera, sigma0, others=others)
    times: dict[str, list[float]] = {"without": [], "with": []}
    for request in requests:
        for label, mpc in (("without", without), ("with", with_margins)):
            start = time.perf_counter()
            mpc.plan(request, camera.observable)
            times[label].append(time.perf_counter() - start)
    median = statistics.median(times["with"]) / statistics.median(times["without"])
    p95 = float(np.percentile(times["with"], 95) / np.percentile(times["without"], 95))
    return median, p95
