"""``mission view``: a finished run replayed in 3-D (Rerun), its files checked first."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from mission.commands.common import add_run_scenario_option
from mission.config.errors import InputError
from mission.procs.outputs import check_output_file
from mission.runs.run_files import previous_summary, run_scenario


def add_parser(commands) -> None:
    """``mission view``'s arguments."""
    parser = commands.add_parser("view", help="replay a run in 3-D (Rerun): native, web or a file")
    parser.add_argument("run", type=Path, metavar="RUN_DIR", help="a run's directory")
    parser.add_argument(
        "--web", action="store_true", help="serve the web viewer on 127.0.0.1 and print its URL"
    )
    parser.add_argument(
        "--save", type=Path, metavar="FILE.rrd", help="write the recording (open: rerun FILE.rrd)"
    )
    add_run_scenario_option(parser)
    parser.set_defaults(handler=view)


def view(args: argparse.Namespace) -> int:
    """``mission view``."""
    run_dir = args.run
    for name in ("gcs.tlog", "records.jsonl"):
        if not (run_dir / name).is_file():
            raise InputError(str(run_dir), "", f"no {name} here (give a run's directory)")
    if (run_dir / "gcs.tlog").stat().st_size == 0:
        raise InputError(str(run_dir / "gcs.tlog"), "", "is empty")
    if args.save is not None:
        check_output_file(args.save, "--save", (".rrd",))
        # Rerun's own log lines would follow ours (a full disk: three of them); what went
        # wrong is said on one line here. RUST_LOG set by the user is kept.
        os.environ.setdefault("RUST_LOG", "off")
    previous = previous_summary(run_dir / "summary.json")
    scenario = run_scenario(run_dir, run_dir, previous, args.scenario)
    from mission.analysis.records_file import RunShape
    from mission.config.resources import map_shape
    from mission.viewer.check import check_run_files
    from mission.viewer.process import ViewerFailed
    from mission.viewer.replay import replay_run, viewer_kind

    shape = RunShape.of(scenario, previous)
    for warning in check_run_files(run_dir, map_shape(scenario), previous, shape):
        print(f"warning: {warning}", file=sys.stderr)

    viewer = viewer_kind(args.web) if args.web or args.save is None else None
    if viewer == "web" and not args.web:
        print("no display for a native viewer: serving the web viewer", file=sys.stderr)
    try:
        return replay_run(run_dir, scenario, viewer, args.save)
    except ViewerFailed as error:
        print(f"view failed: {error}", file=sys.stderr)
        return 1
