"""``mission analyze``: a finished run's metrics recomputed from its tlog, and its figures; a
summary is never made worse by a cut tlog or damaged records (cut, emptied, doubled, or with a
line that is not a cycle's record)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from mission.analysis.records_file import RecordsFile, RunShape, read_records_file
from mission.commands.common import add_run_scenario_option
from mission.config.errors import InputError
from mission.procs.disk_full import fresh, removed_if_disk_fills
from mission.procs.outputs import check_output_dir
from mission.runs.run_files import previous_summary, run_scenario


def add_parser(commands) -> None:
    """``mission analyze``'s arguments."""
    parser = commands.add_parser("analyze", help="recompute a run's metrics from its tlog")
    parser.add_argument(
        "run", type=Path, metavar="DIR|TLOG", help="a run's directory, or its gcs.tlog"
    )
    add_run_scenario_option(parser)
    parser.add_argument(
        "--plots", action="store_true", help="draw the paper's figures into DIR/plots/"
    )
    parser.set_defaults(handler=analyze)


def analyze(args: argparse.Namespace) -> int:
    """``mission analyze``: the tlog read once, for the metrics and the figures."""
    from mission.analysis.metrics import read_tlog
    from mission.analysis.run_metrics import metrics_of
    from mission.world.model import World

    tlog = args.run / "gcs.tlog" if args.run.is_dir() else args.run
    if not tlog.is_file():
        raise InputError(str(args.run), "", "no gcs.tlog here (give a run directory or a tlog)")
    if tlog.stat().st_size == 0:
        raise InputError(str(tlog), "", "is empty")
    summary_path = tlog.parent / "summary.json"
    previous = previous_summary(summary_path)
    scenario = run_scenario(args.run, tlog.parent, previous, args.scenario)
    plots = tlog.parent / "plots"
    if args.plots:
        _check_plots(plots)
    shape = RunShape.of(scenario, previous)
    records = _records_beside(tlog, shape)  # a damaged file refused before the tlog is read
    trace, world = read_tlog(tlog, scenario), World(scenario)
    metrics = metrics_of(trace, world, tlog.parent, scenario)
    if not metrics["control_cycles"]:
        raise InputError(str(tlog), "", "holds no control cycle of a ground station")
    _check_holds_the_summary(tlog, metrics, previous)
    if records is not None:
        _check_records_hold_the_cycles(tlog.parent / "records.jsonl", records, metrics)
    merged = {**previous, **metrics}
    if previous:
        from mission.procs.atomic import write_text_atomically

        write_text_atomically(summary_path, json.dumps(merged, indent=2) + "\n")
    print(json.dumps(metrics, indent=2))  # stdout is the metrics alone; notes go to stderr
    if args.plots:
        from mission.analysis.run_plot import FIGURES, RunLabel, plot_run

        label = RunLabel(scenario.name, previous.get("method"), previous.get("seed"))
        with removed_if_disk_fills(*fresh(plots, *(plots / name for name in FIGURES))):
            written = plot_run(trace, world, tlog.parent / "g", plots, label)
        for path in written:
            print(f"wrote {path}", file=sys.stderr)
    return 0


def _check_plots(plots: Path) -> None:
    """The figures' folder and files can be written (before anything is)."""
    from mission.analysis.run_plot import FIGURES

    check_output_dir(plots, "--plots")
    for name in FIGURES:
        if (plots / name).is_dir():
            raise InputError("command line", "--plots", f"{plots / name} is a directory")


def _records_beside(tlog: Path, shape: RunShape) -> RecordsFile | None:
    """The run's records.jsonl, checked line by line (None: the tlog has none beside it)."""
    path = tlog.parent / "records.jsonl"
    if not path.exists() and not path.is_symlink():
        return None
    if not path.is_file():
        raise InputError(str(path), "", "is not a regular file")
    return read_records_file(path, shape)


def _check_records_hold_the_cycles(path: Path, records: RecordsFile, metrics: dict) -> None:
    """Records of fewer cycles than the tlog's (one fewer where the station stopped between
    a cycle's commands and its record) were cut short or emptied: the summary is kept."""
    cycles, held = metrics["control_cycles"], len(records.records)
    if held > cycles:
        raise InputError(
            str(path),
            "",
            f"holds {held} control cycles' records where the tlog has {cycles}: records of "
            "another run, or added? summary.json is not rewritten",
        )
    if held < cycles - 1:
        raise InputError(
            str(path),
            "",
            f"holds {held} control cycles' records where the tlog has {cycles}: cut short? "
            "summary.json is not rewritten",
        )


def _check_holds_the_summary(tlog: Path, metrics: dict, previous: dict) -> None:
    """A tlog with fewer control cycles than its summary records, or without the completion
    it records, was cut short (a copy interrupted, a full disk): the summary is kept."""
    cycles, recorded = metrics["control_cycles"], previous.get("control_cycles")
    lost = isinstance(recorded, int) and cycles < recorded
    if lost or (previous.get("completed") is True and not metrics.get("completed")):
        completion = "" if metrics.get("completed") else ", no completion,"
        raise InputError(
            str(tlog),
            "",
            f"holds {cycles} control cycles{completion} where summary.json records "
            f"{recorded}{' and a completed run' if previous.get('completed') else ''}: "
            "cut short? summary.json is not rewritten",
        )
