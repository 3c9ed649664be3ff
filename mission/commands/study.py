"""``mission study``: a study file run on an engine (local or Ray), resumable; and the checks
every study gets before it starts."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from mission.api.study_checks import check_study_outputs
from mission.commands.study_verify import add_verify_arguments, verify_command
from mission.config.errors import InputError
from mission.studies.execute import KEEP_CHOICES


def add_parser(commands) -> None:
    """``mission study``'s arguments."""
    parser = commands.add_parser(
        "study",
        help="run a study file (a sweep of scenarios x points x methods x seeds); "
        "write results.csv and report.md",
    )
    parser.add_argument(
        "file",
        type=Path,
        metavar="STUDY",
        help="a study file, or a shipped study's name (smoke, table3, ...)",
    )
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
        choices=KEEP_CHOICES,
        default="all",
        help="of each run's folder: all; logs (all but G's snapshots); summary (and scenario)",
    )
    parser.add_argument(
        "--report-only",
        action="store_true",
        help="run nothing: write report.md, its figures (and Table 3) again from DIR's results.csv",
    )
    parser.add_argument(
        "--historical",
        metavar="WHY",
        help="with --report-only: mark the study historical (its numbers are not today's code's) "
        "in provenance.json and the report's first line",
    )
    add_verify_arguments(parser)
    parser.set_defaults(handler=study)


def study(args: argparse.Namespace) -> int:
    """``mission study``."""
    from mission.studies.spec import load_study

    spec = load_study(args.file, say=lambda text: print(text, file=sys.stderr, flush=True))
    if args.historical is not None and not args.report_only:
        raise InputError("command line", "--historical", "is for --report-only")
    if args.verify is not None:
        if args.report_only:
            raise InputError("command line", "--verify", "runs rows: not with --report-only")
        return verify_command(spec, args)
    if args.against is not None:
        raise InputError("command line", "--against", "is for --verify")
    if args.draw_seed is not None:
        raise InputError("command line", "--draw-seed", "is for --verify N")
    out = args.out or Path("results") / spec.name
    if args.report_only:
        return _report_only(spec, out, args.historical)
    return run_study_command(spec, out, args)


def _report_only(spec, out: Path, historical: str | None) -> int:
    """``--report-only``: the report of ``out``'s results.csv, written again (marked
    historical first, with ``--historical``)."""
    from mission.studies.provenance_file import mark_historical
    from mission.studies.study import rewrite_report

    results = out / "results.csv"
    if not results.is_file():
        raise InputError("command line", "--out", f"no results.csv in {out} to report on")
    check_study_outputs(out, None)
    if historical is not None:
        mark_historical(out, historical)
    rows = rewrite_report(spec, out)
    print(f"report of {rows} runs in {out / 'report.md'}")
    return 0


def run_study_command(spec, out: Path, args: argparse.Namespace) -> int:
    """The study run by the Python API's :func:`~mission.api.studies.conduct`: checked, then
    on the chosen engine, the canary first."""
    from mission.api.studies import conduct

    try:
        outcome = conduct(spec, out, args.engine, args.keep, args.runs, args.jobs, args.address)
    except KeyboardInterrupt:
        print(f"study interrupted; finished runs are kept in {out}: run it again to resume")
        return 130
    print(
        f"{outcome.finished} runs finished, {outcome.skipped} already done, "
        f"{len(outcome.failed)} failed; wall {outcome.wall_time_s:.1f} s; "
        f"results in {out / 'results.csv'}, report in {out / 'report.md'}"
    )
    return 1 if outcome.failed else 0
