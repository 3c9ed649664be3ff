"""``mission study``: run what a study file asks, on an engine, into a folder.

``OUT/runs/<scenario>-<method>-<seed>-<key>/`` holds each run (its summary names the key);
``OUT/results.csv`` and ``OUT/report.md`` (with ``OUT/figures/``) are rewritten from the
finished summaries after every run, so an interrupted study loses nothing, and running it
again skips what is done and ends with the same results and report.
"""

from __future__ import annotations

import json
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol, TextIO

from mission.procs.atomic import write_text_atomically
from mission.procs.machine_speed import REFERENCE_LOOP_S, python_loop_s
from mission.studies.canary import canary_record, canary_runs
from mission.studies.execute import Keep, finished_summary
from mission.studies.local_engine import Done
from mission.studies.provenance_file import (
    made_now,
    read_provenance,
    study_provenance,
    write_provenance,
)
from mission.studies.report import write_report
from mission.studies.results import result_row, results_csv
from mission.studies.results_check import checked_results
from mission.studies.runkeys import StudyRun, code_version, study_runs
from mission.studies.spec import StudySpec, validate_points
from mission.studies.table3 import write_tables

REPORT_EVERY_S = 60.0  # the report and its figures, while runs finish (and at the end)
RUN_CPU_S = 6.0  # CPU-seconds of a run's processes (docs/benchmarks.md), at REFERENCE_LOOP_S
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


def plan_runs(spec: StudySpec, code: str | None = None) -> list[StudyRun]:
    """Every run of the study, keyed (validates every point first)."""
    resolved = validate_points(spec)
    names = {scenario: resolved[(scenario, 0)].name for scenario in spec.scenarios}
    return study_runs(spec, names, code or code_version())


def run_study(
    spec: StudySpec,
    out_dir: Path,
    engine: Engine,
    keep: Keep = "all",
    progress: TextIO = sys.stderr,
    runs_dir: Path | None = None,
    canary: bool = False,
) -> StudyOutcome:
    """Run what is not finished yet and write results.csv, provenance.json and report.md.
    ``runs_dir`` (default ``OUT/runs``) may be shared between studies: a run's folder is
    named by its key, so a run that two studies hold in common is made once. With ``canary``,
    the canary's runs go first (:mod:`mission.studies.canary`)."""
    code = code_version()
    runs = plan_runs(spec, code)
    canaries = canary_runs(code) if canary else []
    runs_dir = runs_dir or out_dir / "runs"
    out_dir.mkdir(parents=True, exist_ok=True)
    runs_dir.mkdir(parents=True, exist_ok=True)
    summaries = finished_summaries(canaries + runs, runs_dir)
    pending = [run for run in canaries + runs if run not in summaries]
    failed: list[str] = []
    already = sum(1 for run in runs if run in summaries)
    outputs = StudyOutputs(out_dir, spec, runs, canaries, code)
    outputs.write(summaries, 0, report=False)  # first: a disk that cannot hold it says so alone
    bar = ProgressBar(len(runs), already, progress, engine.description)
    note = duration_note(len(pending), engine.cores)
    if note:
        progress.write(note + "\n")
    start = last_report = time.monotonic()

    def done(run: StudyRun, summary: dict | None, wall: float) -> None:
        nonlocal last_report
        if summary is not None:
            summaries[run] = summary
        if run in canaries:
            progress.write(canary_line(run, summary) + "\n")
            return
        point = spec.points[run.point].label
        name = run.folder if len(spec.points) == 1 else f"{run.folder} [{point}]"
        if summary is None:
            failed.append(run.folder)
        bar.advance(f"{name}: {_one_line(summary, runs_dir / run.folder)}")
        report = time.monotonic() - last_report > REPORT_EVERY_S
        outputs.write(summaries, len(failed), report)
        last_report = time.monotonic() if report else last_report

    try:
        if pending:
            engine.run(pending, runs_dir, keep, done)
    finally:
        outputs.write(summaries, len(failed), report=True)
    return StudyOutcome(
        sum(1 for run in runs if run in summaries) - already,
        already,
        failed,
        round(time.monotonic() - start, 1),
    )


def finished_summaries(runs: list[StudyRun], runs_dir: Path) -> dict[StudyRun, dict[str, Any]]:
    """The summaries of the runs already finished (by their keys) in ``runs_dir``."""
    summaries = {}
    for run in runs:
        summary = finished_summary(run, runs_dir / run.folder)
        if summary is not None:
            summaries[run] = summary
    return summaries


def canary_line(run: StudyRun, summary: dict | None) -> str:
    """The progress line of a finished canary run."""
    if summary is None:
        return f"canary {run.folder}: FAILED"
    return f"canary {run.folder}: decisions {summary.get('decisions_digest')}"


@dataclass
class StudyOutputs:
    """What a study writes from its finished summaries: results.csv and provenance.json,
    and report.md with its figures (and Table 3 if the study asks)."""

    out_dir: Path
    spec: StudySpec
    runs: list[StudyRun]
    canaries: list[StudyRun]
    code: str
    made: dict[str, Any] | None = None  # made_now(), read at the first write

    def write(self, summaries: dict[StudyRun, dict[str, Any]], failed: int, report: bool) -> None:
        """results.csv and provenance.json; with ``report``, report.md too."""
        spec = self.spec
        rows = [result_row(spec, run, summaries[run]) for run in self.runs if run in summaries]
        write_text_atomically(self.out_dir / "results.csv", results_csv(spec, rows))
        provenance = None
        if self.canaries:
            made = [summaries.get(run) for run in self.canaries]
            numerics = ((made[0] or {}).get("provenance") or {}).get("numerics")
            canary = canary_record(made)
            if self.made is None:
                self.made = made_now(spec.name, self.code)
            provenance = study_provenance(self.made, canary, numerics)
            write_provenance(self.out_dir, provenance)
        if report:
            write_report(self.out_dir, spec, rows, failed, provenance)
            if "table3" in spec.tables:
                write_tables(self.out_dir, rows)


def rewrite_report(spec: StudySpec, out_dir: Path) -> int:
    """report.md, its figures (and Table 3 if the study asks) written again from
    ``out_dir``'s results.csv and provenance.json, running nothing: a report of the code of the
    day from rows of an earlier run of the study. The number of rows. A results.csv that does
    not hold this study's rows is refused (InputError) before anything is written."""
    rows = checked_results(out_dir / "results.csv", plan_runs(spec))  # before any writing
    write_report(out_dir, spec, rows, failed=0, provenance=read_provenance(out_dir))
    if "table3" in spec.tables:
        write_tables(out_dir, rows)
    return len(rows)


def _why_failed(run_dir: Path) -> str:
    """': not exact lockstep ...' where the run finished but its lockstep did not hold."""
    from mission.analysis.lockstep import integrity_note

    try:
        summary = json.loads((run_dir / "summary.json").read_text())
    except (OSError, ValueError):
        return ""
    note = integrity_note(summary) if isinstance(summary, dict) else ""
    return f": {note.removeprefix('; ')}" if note else ""


def _one_line(summary: dict[str, Any] | None, run_dir: Path) -> str:
    """A finished run's progress line: how it ended, or why it failed and where to look."""
    if summary is None:
        return f"FAILED{_why_failed(run_dir)} (see {run_dir})"
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
