"""``mission analyze`` and ``mission view``: the commands that read a finished run's files
(its tlog, records, G snapshots and summary), checking them before they write or show
anything."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from mission.config.errors import InputError
from mission.procs.outputs import check_output_dir, check_output_file


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
    previous = _previous_summary(summary_path)
    scenario = _run_scenario(args.run, tlog.parent, previous, args.scenario)
    plots = tlog.parent / "plots"
    if args.plots:
        _check_plots(plots)
    trace, world = read_tlog(tlog, scenario), World(scenario)
    metrics = metrics_of(trace, world, tlog.parent, scenario)
    if not metrics["control_cycles"]:
        raise InputError(str(tlog), "", "holds no control cycle of a ground station")
    _check_holds_the_summary(tlog, metrics, previous)
    merged = {**previous, **metrics}
    if previous:
        from mission.procs.atomic import write_text_atomically

        write_text_atomically(summary_path, json.dumps(merged, indent=2) + "\n")
    print(json.dumps(metrics, indent=2))  # stdout is the metrics alone; notes go to stderr
    if args.plots:
        from mission.analysis.run_plot import RunLabel, plot_run

        label = RunLabel(scenario.name, previous.get("method"), previous.get("seed"))
        for path in plot_run(trace, world, tlog.parent / "g", plots, label):
            print(f"wrote {path}", file=sys.stderr)
    return 0


def _run_scenario(given: Path, run_dir: Path, previous: dict, explicit: str | None):
    """The scenario a run ran: ``--scenario``, else the scenario.yaml a study's run carries,
    else the file or name its summary.json names."""
    from mission.config.scenario import load_scenario

    beside = run_dir / "scenario.yaml"
    source = previous.get("scenario_source")
    if source is not None and not Path(source).is_file():
        source = None  # resolved on another machine (a Ray node's temporary folder)
    scenario_name = (
        explicit
        or (str(beside) if beside.is_file() else None)
        or source
        or previous.get("scenario")
    )
    if scenario_name is None:
        raise InputError(str(given), "--scenario", "unknown scenario: give --scenario")
    return load_scenario(scenario_name)


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
    previous = _previous_summary(run_dir / "summary.json")
    scenario = _run_scenario(run_dir, run_dir, previous, args.scenario)
    from mission.config.resources import map_shape
    from mission.viewer.check import check_run_files
    from mission.viewer.process import ViewerFailed
    from mission.viewer.replay import replay_run, viewer_kind

    for warning in check_run_files(run_dir, map_shape(scenario), previous):
        print(f"warning: {warning}", file=sys.stderr)

    viewer = viewer_kind(args.web) if args.web or args.save is None else None
    if viewer == "web" and not args.web:
        print("no display for a native viewer: serving the web viewer", file=sys.stderr)
    try:
        return replay_run(run_dir, scenario, viewer, args.save)
    except ViewerFailed as error:
        print(f"view failed: {error}", file=sys.stderr)
        return 1


def _check_plots(plots: Path) -> None:
    """The figures' folder and files can be written (before anything is)."""
    from mission.analysis.run_plot import FIGURES

    check_output_dir(plots, "--plots")
    for name in FIGURES:
        if (plots / name).is_dir():
            raise InputError("command line", "--plots", f"{plots / name} is a directory")


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


def _previous_summary(path: Path) -> dict:
    """The summary.json beside a tlog ({} if there is none); one line naming it if it is not
    a JSON object."""
    if not path.is_file():
        return {}
    try:
        summary = json.loads(path.read_text(encoding="utf-8"))
    except (ValueError, OSError) as error:
        raise InputError(str(path), "", f"not a readable JSON summary ({error})") from None
    if not isinstance(summary, dict):
        raise InputError(str(path), "", "not a JSON object")
    return summary
