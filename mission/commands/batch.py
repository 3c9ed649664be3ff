"""``mission batch``: a study of one point (scenarios x methods x seeds) that writes Table 3."""

from __future__ import annotations

import argparse
from pathlib import Path

from mission.commands.common import add_realtime_arguments, realtime_speedup
from mission.commands.study import run_study_command
from mission.config.errors import InputError


def add_parser(commands) -> None:
    """``mission batch``'s arguments."""
    parser = commands.add_parser(
        "batch", help="run scenarios x methods x seeds in parallel; write Table 3"
    )
    parser.add_argument(
        "scenarios",
        nargs="*",
        default=["along", "wall"],
        metavar="SCENARIO",
        help="embedded names or YAML paths",
    )
    parser.add_argument("--trials", type=int, default=15, help="seeds 0..N-1 (default 15)")
    parser.add_argument("--methods", default="ac,nac", help="comma-separated (default ac,nac)")
    parser.add_argument("--jobs", type=int, default=2, help="runs in parallel")
    parser.add_argument(
        "--out", type=Path, default=Path("logs/batch"), help="default logs/batch (resumable)"
    )
    add_realtime_arguments(parser, "every run")
    parser.set_defaults(handler=batch)


def batch(args: argparse.Namespace) -> int:
    """``mission batch``: Table 3's study of the given scenarios, methods and seeds."""
    from mission.studies.spec import METHODS, Point, StudySpec, scenario_reference

    if not 1 <= args.trials <= 1000:
        raise InputError("command line", "--trials", f"must be in [1, 1000], got {args.trials}")
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    if not methods or any(m not in METHODS for m in methods):
        raise InputError("command line", "--methods", f"expected ac and/or nac: {args.methods!r}")
    scenarios = [scenario_reference(Path.cwd(), s, "SCENARIO") for s in args.scenarios]
    spec = StudySpec(
        name="batch",
        description="The paper's Table 3: AC and NAC over paired seeds.",
        source=Path("command line"),
        scenarios=tuple(scenarios),
        methods=tuple(dict.fromkeys(methods)),
        seeds=tuple(range(args.trials)),
        points=(Point(()),),
        tables=("table3",),
        speedup=realtime_speedup(args),
    )
    args.engine, args.address, args.keep, args.runs = "local", None, "all", None
    status = run_study_command(spec, args.out, args)
    if (args.out / "table.md").is_file():
        print((args.out / "table.md").read_text(), end="")
    return status
