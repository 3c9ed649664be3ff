"""``mission study``: a study file run on an engine (local or Ray), resumable; and the checks
every study gets before it starts."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from mission.commands.common import preflight
from mission.config.errors import InputError
from mission.procs.interrupts import StopRequest
from mission.procs.outputs import check_output_dir

MAX_JOBS = 256


def add_parser(commands) -> None:
    """``mission study``'s arguments."""
    parser = commands.add_parser(
        "study",
        help="run a study file (a sweep of scenarios x points x methods x seeds); "
        "write results.csv and report.md",
    )
    parser.add_argument("file", type=Path, metavar="FILE.yaml", help="the study file")
    parser.add_argument(
        "--engine",
        choices=["local", "ray"],
        default="local",
        help="local: child processes of this one; ray: Ray tasks (pip install -e '.[ray]')",
    )
    parser.add_argument(
        "--address",
        metavar="ADDR",
        help="--engine ray: the cluster to join (default: RAY_ADDRESS, else a Ray started here)",
    )
    parser.add_argument(
        "--jobs",
        type=int,
        help="runs at once (default: local, this machine's cores; ray, as the cluster allows)",
    )
    parser.add_argument(
        "--out", type=Path, metavar="DIR", help="where it goes (default results/NAME; resumable)"
    )
    parser.add_argument(
        "--runs",
        type=Path,
        metavar="DIR",
        help="the runs' folders (default DIR/runs); studies that share one make a run they "
        "have in common once",
    )
    parser.add_argument(
        "--keep",
        choices=["all", "logs", "summary"],
        default="all",
        help="of each run's folder: all; logs (all but G's snapshots); summary (and scenario)",
    )
    parser.add_argument(
        "--report-only",
        action="store_true",
        help="run nothing: write report.md, its figures (and Table 3) again from DIR's results.csv",
    )
    parser.set_defaults(handler=study)


def study(args: argparse.Namespace) -> int:
    """``mission study``."""
    from mission.studies.spec import load_study

    spec = load_study(args.file)
    out = args.out or Path("results") / spec.name
    if args.report_only:
        return _report_only(spec, out)
    return run_study_command(spec, out, args)


def _report_only(spec, out: Path) -> int:
    """``--report-only``: the report of ``out``'s results.csv, written again."""
    from mission.studies.study import rewrite_report

    results = out / "results.csv"
    if not results.is_file():
        raise InputError("command line", "--out", f"no results.csv in {out} to report on")
    _check_study_outputs(out, None)
    rows = rewrite_report(spec, out)
    print(f"report of {rows} runs in {out / 'report.md'}")
    return 0


def run_study_command(spec, out: Path, args: argparse.Namespace) -> int:
    """Check everything, then run the study on the chosen engine (which keys every run
    before it starts any)."""
    from mission.studies.study import run_study

    jobs = args.jobs
    if jobs is not None and not 1 <= jobs <= MAX_JOBS:
        raise InputError("command line", "--jobs", f"must be in [1, {MAX_JOBS}], got {jobs}")
    check_output_dir(out, "--out")
    if args.runs is not None:
        check_output_dir(args.runs, "--runs")
    _check_study_outputs(out, args.runs)
    repeated = [s for i, s in enumerate(spec.scenarios) if s in spec.scenarios[:i]]
    if repeated:
        field = "SCENARIO" if spec.source == Path("command line") else "scenarios"
        raise InputError(str(spec.source), field, f"lists {repeated[0]} twice")
    names = _check_scenarios(spec)
    if len(set(names.values())) != len(names):
        raise InputError(str(spec.source), "scenarios", "two scenarios have the same name")
    engine = _engine(args)
    # Ctrl-C and SIGTERM stop the study, even where it was started with SIGINT ignored (in the
    # background): then `kill -INT` cancels it as Ctrl-C would.
    try:
        with StopRequest():
            outcome = run_study(spec, out, engine, args.keep, runs_dir=args.runs)
    except KeyboardInterrupt:
        print(f"study interrupted; finished runs are kept in {out}: run it again to resume")
        return 130
    print(
        f"{outcome.finished} runs finished, {outcome.skipped} already done, "
        f"{len(outcome.failed)} failed; wall {outcome.wall_time_s:.1f} s; "
        f"results in {out / 'results.csv'}, report in {out / 'report.md'}"
    )
    return 1 if outcome.failed else 0


STUDY_FILES = ("results.csv", "report.md", "table.md", "table.csv", "boxplots.png")


STUDY_FOLDERS = ("figures", "runs")


def _check_study_outputs(out: Path, runs: Path | None) -> None:
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


def _engine(args: argparse.Namespace):
    if args.engine == "ray":
        from mission.studies.ray_engine import RayEngine, check_reachable, require_ray

        require_ray()
        check_reachable(args.address, "--address" if args.address else "RAY_ADDRESS")
        return RayEngine(args.address, args.jobs)
    if args.address is not None:
        raise InputError("command line", "--address", "is for --engine ray")
    from mission.studies.local_engine import LocalEngine

    return LocalEngine(args.jobs or os.cpu_count() or 1)
