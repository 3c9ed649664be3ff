"""``mission study``: run what a study file asks, on an engine, into a folder.

``OUT/runs/<scenario>-<method>-<seed>-<key>/`` holds each run (its summary names the key);
``OUT/results.csv`` and ``OUT/report.md`` (with ``OUT/figures/``) are rewritten from the
finished summaries after every run, so an interrupted study loses nothing, and running it
again skips what is done and ends with the same results and report.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol, TextIO

from mission.procs.atomic import write_text_atomically
from mission.procs.machine_speed import REFERENCE_LOOP_S, python_loop_s
from mission.studies.execute import Keep, finished_summary
from mission.studies.local_engine import Done
from mission.studies.report import write_report
from mission.studies.results import read_results_csv, result_row, results_csv
from mission.studies.runkeys import StudyRun, code_version, study_runs
from mission.studies.spec import StudySpec, validate_points
from mission.studies.table3 import write_tables

REPORT_EVERY_S = 60.0  # the report and its figures, while runs finish (and at the end)
RUN_CPU_S = 7.0  # CPU-seconds of a run's processes (docs/benchmarks.md), at REFERENCE_LOOP_S
WARN_AFTER_S = 3600.0  # a study expected to take longer is announced with its estimate


class Engine(Protocol):
    """Runs a list of study runs, reporting each as it finishes."""

    description: str

    @property
    def cores(self) -> int | None:
        """How many runs go at once (None: as many as a cluster has cores)."""

    def run(self, runs: list[StudyRun], runs_dir: Path, keep: Keep, done: Done) -> None:
        """Run them all; stop what is running on any exit."""


@dataclass(frozen=True)
class StudyOutcome:
    """What a call of :func:`run_study` did."""

    finished: int
    skipped: int
    failed: list[str]
    wall_time_s: float


def plan_runs(spec: StudySpec) -> list[StudyRun]:
    """Every run of the study, keyed (validates every point first)."""
    resolved = validate_points(spec)
    names = {scenario: resolved[(scenario, 0)].name for scenario in spec.scenarios}
    return study_runs(spec, names, code_version())


def run_study(
    spec: StudySpec,
    out_dir: Path,
    engine: Engine,
    keep: Keep = "all",
    progress: TextIO = sys.stderr,
    runs_dir: Path | None = None,
) -> StudyOutcome:
    """Run what is not finished yet and write results.csv and report.md. ``runs_dir``
    (default ``OUT/runs``) may be shared between studies: a run's folder is named by its key,
    so a run that two studies hold in common is made once."""
    runs = plan_runs(spec)
    runs_dir = runs_dir or out_dir / "runs"
    out_dir.mkdir(parents=True, exist_ok=True)
    runs_dir.mkdir(parents=True, exist_ok=True)
    summaries: dict[StudyRun, dict[str, Any]] = {}
    for run in runs:
        summary = finished_summary(run, runs_dir / run.folder)
        if summary is not None:
            summaries[run] = summary
    pending = [run for run in runs if run not in summaries]
    failed: list[str] = []
    bar = ProgressBar(len(runs), len(summaries), progress, engine.description)
    note = duration_note(len(pending), engine.cores)
    if note:
        progress.write(note + "\n")
    start = last_report = time.monotonic()

    def done(run: StudyRun, summary: dict | None, wall: float) -> None:
        nonlocal last_report
        point = spec.points[run.point].label
        name = run.folder if len(spec.points) == 1 else f"{run.folder} [{point}]"
        if summary is None:
            failed.append(run.folder)
            bar.advance(f"{name}: FAILED (see {runs_dir / run.folder})")
        else:
            summaries[run] = summary
            bar.advance(f"{name}: {_one_line(summary)}")
        report = time.monotonic() - last_report > REPORT_EVERY_S
        write_outputs(out_dir, spec, runs, summaries, len(failed), report)
        last_report = time.monotonic() if report else last_report

    try:
        if pending:
            engine.run(pending, runs_dir, keep, done)
    finally:
        write_outputs(out_dir, spec, runs, summaries, len(failed), report=True)
    return StudyOutcome(
        len(summaries) - (len(runs) - len(pending)),
        len(runs) - len(pending),
        failed,
        round(time.monotonic() - start, 1),
    )


def write_outputs(
    out_dir: Path,
    spec: StudySpec,
    runs: list[StudyRun],
    summaries: dict[StudyRun, dict[str, Any]],
    failed: int,
    report: bool,
) -> None:
    """results.csv from the summaries; with ``report``, report.md and its figures too (and
    Table 3 if the study asks)."""
    rows = [result_row(spec, run, summaries[run]) for run in runs if run in summaries]
    write_text_atomically(out_dir / "results.csv", results_csv(spec, rows))
    if report:
        write_report(out_dir, spec, rows, failed)
        if "table3" in spec.tables:
            write_tables(out_dir, rows)


def rewrite_report(spec: StudySpec, out_dir: Path) -> int:
    """report.md, its figures (and Table 3 if the study asks) written again from
    ``out_dir``'s results.csv, running nothing: a report of the code of the day from rows of
    an earlier run of the study. The number of rows."""
    rows = read_results_csv((out_dir / "results.csv").read_text(encoding="utf-8"))
    write_report(out_dir, spec, rows, failed=0)
    if "table3" in spec.tables:
        write_tables(out_dir, rows)
    return len(rows)


def _one_line(summary: dict[str, Any]) -> str:
    done = (
        f"completed at {summary['completion_time_s']:.1f} s"
        if summary["completed"]
        else f"STOPPED ({summary['stopped']})"
        if summary.get("stopped")
        else "NOT completed"
    )
    return (
        f"{done}, {summary['multipath_steps_total']} steps in multipath, "
        f"wall {summary['wall_time_s']:.1f} s"
    )


def duration_note(runs: int, cores: int | None) -> str | None:
    """What a study of ``runs`` will take, said before it starts when that is over an hour
    (at this machine's speed, from the benchmarks' cost of a run); None when it is not."""
    per_core = runs * RUN_CPU_S
    if per_core / (cores or 1) < WARN_AFTER_S / 4:  # surely under an hour: no measuring
        return None
    per_core *= python_loop_s(repeats=1) / REFERENCE_LOOP_S
    wall = per_core / (cores or 1)
    if wall < WARN_AFTER_S:
        return None
    where = f"on {cores} cores" if cores else "per core of the cluster"
    return (
        f"study: {runs} runs to go, about {_span(wall)} {where} "
        f"({RUN_CPU_S:g} CPU-seconds a run on this machine: `mission bench --only run`)"
    )


def _span(seconds: float) -> str:
    """1.5 h, 3.2 days."""
    hours = seconds / 3600
    return f"{hours:.1f} h" if hours < 48 else f"{hours / 24:.1f} days"


class ProgressBar:
    """``[#####.....] 12/60  mm:ss left  <last run>`` lines, one per finished run."""

    def __init__(self, total: int, done: int, stream: TextIO, engine: str) -> None:
        self.total, self.done, self.stream = total, done, stream
        self.started, self.start_done = time.monotonic(), done
        self.stream.write(f"study: {total} runs, {done} already finished; {engine}\n")
        self.stream.flush()

    def advance(self, message: str) -> None:
        """Count one more finished run and print the bar."""
        self.done += 1
        width = 30
        filled = round(width * self.done / max(self.total, 1))
        elapsed = time.monotonic() - self.started
        rate = elapsed / max(self.done - self.start_done, 1)
        left = int(rate * (self.total - self.done))
        self.stream.write(
            f"[{'#' * filled}{'.' * (width - filled)}] {self.done}/{self.total} "
            f"{left // 60:02d}:{left % 60:02d} left  {message}\n"
        )
        self.stream.flush()
