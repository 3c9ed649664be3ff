"""The study engines' benchmark: one 20-run study (Along, AC and NAC, ten seeds, full runs) on
the local engine and on a Ray started for it on this machine, both with two runs at a time."""

from __future__ import annotations

import io
import os
import tempfile
import time
from pathlib import Path

from mission.bench.result import BenchResult
from mission.procs.machine_speed import children_cpu_s

BENCH_STUDY = "name: bench\nscenarios: [along]\nmethods: [ac, nac]\nseeds: 10\n"
JOBS = 2


def bench_studies() -> list[BenchResult]:
    """``study_runs_per_hour`` of the local engine, how busy it kept the cores
    (``study_core_use``: its runs' CPU seconds over wall seconds x jobs, start-ups and
    analyses included) and, with Ray installed, ``ray_over_local_wall_ratio`` (Ray's start and
    stop included)."""
    from mission.studies.local_engine import LocalEngine
    from mission.studies.spec import load_study

    with tempfile.TemporaryDirectory(prefix="bench-study-") as temp:
        path = Path(temp) / "bench.yaml"
        path.write_text(BENCH_STUDY)
        spec = load_study(path)
        before = children_cpu_s()
        local = _wall(spec, Path(temp) / "local", LocalEngine(JOBS))
        core_use = (children_cpu_s() - before) / (local * min(JOBS, os.cpu_count() or 1))
        per_hour = spec.size / local * 3600
        results = [
            BenchResult("study_runs_per_hour", per_hour, "runs/h", "reference", None),
            BenchResult("study_core_use", core_use, "", ">= 0.90", core_use >= 0.90),
        ]
        try:
            import ray  # noqa: F401
        except ImportError:
            return results
        from mission.studies.ray_engine import RayEngine

        ratio = _wall(spec, Path(temp) / "ray", RayEngine(None, JOBS)) / local
    results.append(BenchResult("ray_over_local_wall_ratio", ratio, "x", "<= 1.10", ratio <= 1.10))
    return results


def _wall(spec, out: Path, engine) -> float:
    """Wall seconds of the whole study on ``engine``, from nothing done."""
    from mission.studies.study import run_study

    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    start = time.monotonic()
    outcome = run_study(spec, out, engine, keep="summary", progress=io.StringIO())
    wall = time.monotonic() - start
    if outcome.failed:
        raise RuntimeError(f"bench study: runs failed: {outcome.failed}")
    return wall
