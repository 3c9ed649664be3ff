"""What several commands share: the scenario argument, real time's arguments, the checks a
run's files get before any process starts, and a figure's output path."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from mission.config.errors import InputError
from mission.config.run_outputs import DEFAULT_SCENARIO
from mission.config.scenario import embedded_scenario_names
from mission.procs.command_line import check_speedup
from mission.procs.outputs import check_output_dir, check_output_file


def add_scenario_argument(parser: argparse.ArgumentParser) -> None:
    """The optional positional scenario (default: the embedded default)."""
    parser.add_argument(
        "scenario",
        nargs="?",
        default=DEFAULT_SCENARIO,
        help=f"embedded name ({', '.join(embedded_scenario_names())}) or YAML path",
    )


def add_run_scenario_option(parser: argparse.ArgumentParser) -> None:
    """``--scenario`` of the commands that read a finished run."""
    parser.add_argument("--scenario", help="scenario of the run (default: from summary.json)")


def add_realtime_arguments(parser: argparse.ArgumentParser, what: str) -> None:
    """``--realtime`` and ``--speedup`` (read with :func:`realtime_speedup`)."""
    parser.add_argument(
        "--realtime", action="store_true", help=f"{what} in real time instead of lockstep"
    )
    parser.add_argument(
        "--speedup", type=float, help="with --realtime: times faster, 0.1-1000 (default 1)"
    )


def realtime_speedup(args: argparse.Namespace) -> float | None:
    """The real-time speed-up (None: lockstep); --speedup only with --realtime."""
    if not args.realtime:
        if args.speedup is not None:
            raise InputError("command line", "--speedup", "is for --realtime runs (add --realtime)")
        return None
    speedup = 1.0 if args.speedup is None else args.speedup
    check_speedup(speedup)
    if args.speedup is None:
        print(
            "real time at 1x: a run takes as long as its flight (minutes); "
            "--speedup X runs X times faster",
            file=sys.stderr,
        )
    return speedup


def check_figure_path(path: Path, flag: str, made: Path | None = None) -> None:
    """A figure's path; its folder may be ``made`` (checked as a folder this command makes)."""
    from mission.analysis.figures import FIGURE_SUFFIXES

    if made is not None and Path(path).parent.resolve() == Path(made).resolve():
        check_output_dir(made, flag)
        if Path(path).is_dir() or Path(path).suffix.lower() not in FIGURE_SUFFIXES:
            check_output_file(path, flag, FIGURE_SUFFIXES)  # says which
        return
    check_output_file(path, flag, FIGURE_SUFFIXES)
