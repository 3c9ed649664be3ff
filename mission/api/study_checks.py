"""What every study command checks before anything is written (its arguments, the output
folders, the scenarios and their files), and the engine it then runs on."""

from __future__ import annotations

import os
from pathlib import Path

from mission.config.errors import InputError
from mission.procs.outputs import check_output_dir
from mission.runs.preflight import preflight

MAX_JOBS = 256


def checked_engine(
    spec, out: Path, jobs: int | None, runs: Path | None, engine: str, address: str | None
):
    """Every check a study's run gets before anything is written (the arguments, the output
    folders, the scenarios and their files); then the engine (``local`` or ``ray``)."""
    if jobs is not None and not 1 <= jobs <= MAX_JOBS:
        raise InputError("command line", "--jobs", f"must be in [1, {MAX_JOBS}], got {jobs}")
    check_output_dir(out, "--out")
    if runs is not None:
        check_output_dir(runs, "--runs")
    check_study_outputs(out, runs)
    repeated = [s for i, s in enumerate(spec.scenarios) if s in spec.scenarios[:i]]
    if repeated:
        field = "SCENARIO" if spec.source == Path("command line") else "scenarios"
        raise InputError(str(spec.source), field, f"lists {repeated[0]} twice")
    names = _check_scenarios(spec)
    if len(set(names.values())) != len(names):
        raise InputError(str(spec.source), "scenarios", "two scenarios have the same name")
    return _engine(engine, address, jobs)


STUDY_FILES = (
    "results.csv",
    "report.md",
    "provenance.json",
    "verify.md",
    "table.md",
    "table.csv",
    "boxplots.png",
)


STUDY_FOLDERS = ("figures", "runs")


def check_study_outputs(out: Path, runs: Path | None) -> None:
    """What a study writes into ``out`` is not already there as the wrong kind of thing."""
    for name in STUDY_FILES:
        if (out / name).is_dir():
            raise InputError("command line", "--out", f"{out / name} is a directory")
    for name in STUDY_FOLDERS:
        if name == "runs" and runs is not None:
            continue
        if (out / name).exists() and not (out / name).is_dir():
            raise InputError("command line", "--out", f"{out / name} is a file, not a directory")


def _check_scenarios(spec) -> dict[str, str]:
    """Every resolved scenario's files (plans, mesh, sky) checked; {reference: name}."""
    from mission.studies.spec import validate_points

    resolved = validate_points(spec)
    for scenario in resolved.values():
        preflight(scenario)
    return {reference: resolved[(reference, 0)].name for reference in spec.scenarios}


def _engine(engine: str, address: str | None, jobs: int | None):
    if engine == "ray":
        from mission.studies.ray_engine import RayEngine, check_reachable, require_ray

        require_ray()
        check_reachable(address, "--address" if address else "RAY_ADDRESS")
        return RayEngine(address, jobs)
    if address is not None:
        raise InputError("command line", "--address", "is for --engine ray")
    from mission.studies.local_engine import LocalEngine

    return LocalEngine(jobs or os.cpu_count() or 1)
