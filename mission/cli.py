"""``python -m mission``: the project's main command line."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path

from mission import run_files_commands, study_commands, subcommands
from mission.link.impairment import add_link_arguments
from mission.procs.cli_common import (
    OneLineArgumentParser,
    program_name,
    run_guarded,
)

DEFAULT_SCENARIO = "along"


def build_parser() -> OneLineArgumentParser:
    """The argument parser with every subcommand."""
    parser = OneLineArgumentParser(
        prog=program_name("mission", "mission"),
        description="Run, batch, analyse and inspect missions of the bridge-inspection UAVs.",
    )
    commands = parser.add_subparsers(
        dest="command", required=True, metavar="COMMAND", parser_class=OneLineArgumentParser
    )
    _add_world_parser(commands)
    _add_plan_parser(commands)
    _add_analyze_parser(commands)
    _add_view_parser(commands)
    _add_bench_parser(commands)
    _add_run_parser(commands)
    _add_batch_parser(commands)
    _add_study_parser(commands)
    return parser


def _add_world_parser(commands) -> None:
    """``mission world``'s arguments."""
    world = commands.add_parser("world", help="inspect a scenario's world (GNSS, structure, zones)")
    world.add_argument(
        "scenario",
        nargs="?",
        default=DEFAULT_SCENARIO,
        help="embedded scenario name (along, wall) or YAML path",
    )
    world.add_argument(
        "--at",
        nargs=3,
        type=float,
        metavar=("X", "Y", "Z"),
        help="print GNSS facts at this ENU point as one JSON object",
    )
    world.add_argument(
        "--plot",
        type=Path,
        metavar="FILE.png|pdf|svg",
        help="draw structure, zones, sky plot and sigma_0 slices",
    )


def _add_plan_parser(commands) -> None:
    """``mission plan``'s arguments."""
    plan = commands.add_parser("plan", help="plan the support UAVs' paths; write waypoint files")
    plan.add_argument(
        "scenario",
        nargs="?",
        default=DEFAULT_SCENARIO,
        help="embedded name (along, wall) or YAML path",
    )
    plan.add_argument(
        "--out",
        type=Path,
        metavar="DIR",
        help="directory for the files (default: the scenario's waypoints_dir)",
    )
    plan.add_argument("--plot", type=Path, metavar="FILE.png|pdf|svg", help="draw the plan")


def _add_analyze_parser(commands) -> None:
    """``mission analyze``'s arguments."""
    analyze = commands.add_parser("analyze", help="recompute a run's metrics from its tlog")
    analyze.add_argument(
        "run", type=Path, metavar="DIR|TLOG", help="a run's directory, or its gcs.tlog"
    )
    analyze.add_argument("--scenario", help="scenario of the run (default: from summary.json)")
    analyze.add_argument(
        "--plots", action="store_true", help="draw the paper's figures into DIR/plots/"
    )


def _add_view_parser(commands) -> None:
    """``mission view``'s arguments."""
    view = commands.add_parser("view", help="replay a run in 3-D (Rerun): native, web or a file")
    view.add_argument("run", type=Path, metavar="RUN_DIR", help="a run's directory")
    view.add_argument(
        "--web", action="store_true", help="serve the web viewer on 127.0.0.1 and print its URL"
    )
    view.add_argument(
        "--save", type=Path, metavar="FILE.rrd", help="write the recording (open: rerun FILE.rrd)"
    )
    view.add_argument("--scenario", help="scenario of the run (default: from summary.json)")


def _add_bench_parser(commands) -> None:
    """``mission bench``'s arguments."""
    bench = commands.add_parser("bench", help="run the benchmarks and print their medians")
    bench.add_argument("--json", action="store_true", help="print one JSON object")
    bench.add_argument(
        "--only",
        action="append",
        choices=["world", "vehicle", "gcs", "margins", "run", "study", "view"],
        help="run only this group (repeatable)",
    )


def _add_run_parser(commands) -> None:
    """``mission run``'s arguments."""
    run = commands.add_parser("run", help="run a mission: vehicle processes + ground station")
    run.add_argument(
        "scenario",
        nargs="?",
        default=DEFAULT_SCENARIO,
        help="embedded name (along, wall) or YAML path",
    )
    run.add_argument(
        "--method",
        choices=["ac", "nac"],
        default="ac",
        help="ac: adaptive control (G learned); nac: the baseline without the update",
    )
    run.add_argument("--seed", type=int, default=0, help="seed of every random draw of the run")
    run.add_argument(
        "--out", type=Path, metavar="DIR", help="default logs/<scenario>-<method>-<seed>-<time>/"
    )
    run.add_argument("--realtime", action="store_true", help="real time instead of lockstep")
    run.add_argument(
        "--speedup", type=float, help="with --realtime: times faster, 0.1-1000 (default 1)"
    )
    run.add_argument(
        "--signing-key", type=Path, metavar="FILE", help="sign every link (32-byte secret)"
    )
    run.add_argument(
        "--observer",
        metavar="HOST:PORT",
        help="every vehicle also streams here (QGroundControl, MAVProxy); use with --realtime",
    )
    add_link_arguments(run)
    run.add_argument(
        "--mpc-helper",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="the ground station shares the support MPCs with a helper process "
        "(default: with two or more cores; same results either way)",
    )
    run.add_argument(
        "--process-start",
        choices=["fork", "exec"],
        default="fork",
        help="fork: the ground station and the vehicles are forked from this process, the "
        "vehicles after one import of their code (exec where forking is unsafe); exec: each is "
        "started as python -m ground_station / vehicle_sim (slower; ps shows its command "
        "line). Same results either way",
    )
    run.add_argument(
        "--view",
        nargs="?",
        const="auto",
        choices=["auto", "web", "native"],
        help="stream the run to a Rerun viewer (auto: native with a display, else web)",
    )
    run.add_argument("--exit-with-parent", action="store_true", help=argparse.SUPPRESS)


def _add_batch_parser(commands) -> None:
    """``mission batch``'s arguments."""
    batch = commands.add_parser(
        "batch", help="run scenarios x methods x seeds in parallel; write Table 3"
    )
    batch.add_argument(
        "scenarios",
        nargs="*",
        default=["along", "wall"],
        metavar="SCENARIO",
        help="embedded names or YAML paths",
    )
    batch.add_argument("--trials", type=int, default=15, help="seeds 0..N-1 (default 15)")
    batch.add_argument("--methods", default="ac,nac", help="comma-separated (default ac,nac)")
    batch.add_argument("--jobs", type=int, default=2, help="runs in parallel")
    batch.add_argument(
        "--out", type=Path, default=Path("logs/batch"), help="default logs/batch (resumable)"
    )
    batch.add_argument(
        "--realtime", action="store_true", help="every run in real time instead of lockstep"
    )
    batch.add_argument(
        "--speedup", type=float, help="with --realtime: times faster, 0.1-1000 (default 1)"
    )


def _add_study_parser(commands) -> None:
    """``mission study``'s arguments."""
    study = commands.add_parser(
        "study",
        help="run a study file (a sweep of scenarios x points x methods x seeds); "
        "write results.csv and report.md",
    )
    study.add_argument("file", type=Path, metavar="FILE.yaml", help="the study file")
    study.add_argument(
        "--engine",
        choices=["local", "ray"],
        default="local",
        help="local: child processes of this one; ray: Ray tasks (pip install -e '.[ray]')",
    )
    study.add_argument(
        "--address",
        metavar="ADDR",
        help="--engine ray: the cluster to join (default: RAY_ADDRESS, else a Ray started here)",
    )
    study.add_argument(
        "--jobs",
        type=int,
        help="runs at once (default: local, this machine's cores; ray, as the cluster allows)",
    )
    study.add_argument(
        "--out", type=Path, metavar="DIR", help="where it goes (default results/NAME; resumable)"
    )
    study.add_argument(
        "--runs",
        type=Path,
        metavar="DIR",
        help="the runs' folders (default DIR/runs); studies that share one make a run they "
        "have in common once",
    )
    study.add_argument(
        "--keep",
        choices=["all", "logs", "summary"],
        default="all",
        help="of each run's folder: all; logs (all but G's snapshots); summary (and scenario)",
    )


def main(argv: Sequence[str] | None = None) -> int:
    """Parse arguments and dispatch to the chosen command."""
    args = build_parser().parse_args(argv)
    command = {
        "world": subcommands.world,
        "run": subcommands.run,
        "bench": subcommands.bench,
        "analyze": run_files_commands.analyze,
        "view": run_files_commands.view,
        "plan": subcommands.plan,
        "batch": study_commands.batch,
        "study": study_commands.study,
    }[args.command]
    return command(args)


def entry_point(argv: Sequence[str] | None = None) -> int:
    """Run the CLI with one-line errors and exit status 2 on bad input."""
    return run_guarded(main, argv)
