"""``mission batch``: every (scenario, method, seed) as its own ``mission run`` process.

J runs go in parallel; seeds are shared between methods (paired trials). Each run writes its
own ``summary.json`` when it finishes, so re-running the same batch into the same directory
skips what is done and an interrupted batch loses nothing. ``results.csv``, ``table.md``,
``table.csv`` and ``boxplots.png`` are rewritten from the summaries after every finished run.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TextIO

from mission.procs.cli_common import child_environment
from mission.runs.batch_table import write_tables
from mission.runs.trials import Trial

POLL_S = 0.2


@dataclass(frozen=True)
class BatchOptions:
    """What a batch runs and where."""

    trials: list[Trial]
    out_dir: Path
    jobs: int


def finished_summary(run_dir: Path, trial: Trial) -> dict[str, Any] | None:
    """The run's summary if it finished as this trial, else None."""
    path = run_dir / "summary.json"
    try:
        summary = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    if (summary.get("scenario"), summary.get("method"), summary.get("seed")) != (
        trial.scenario_name,
        trial.method,
        trial.seed,
    ):
        return None
    return summary


def run_batch(options: BatchOptions, progress: TextIO = sys.stderr) -> dict[str, Any]:
    """Run what is not finished yet; return {finished, failed, skipped, wall_time_s}."""
    runs_dir = options.out_dir / "runs"
    runs_dir.mkdir(parents=True, exist_ok=True)
    summaries: dict[Trial, dict[str, Any]] = {}
    pending: list[Trial] = []
    for trial in options.trials:
        summary = finished_summary(runs_dir / trial.key, trial)
        if summary is None:
            pending.append(trial)
        else:
            summaries[trial] = summary
    skipped = len(summaries)
    failed: list[str] = []
    bar = ProgressBar(len(options.trials), skipped, progress)
    start = time.monotonic()

    def finish(trial: Trial, status: int) -> None:
        summary = finished_summary(runs_dir / trial.key, trial)
        if status == 0 and summary is not None:
            summaries[trial] = summary
            bar.advance(f"{trial.key}: {_one_line(summary)}")
        else:
            failed.append(trial.key)
            bar.advance(f"{trial.key}: FAILED (exit {status}, see {runs_dir / trial.key})")
        write_tables(options.out_dir, options.trials, summaries)

    write_tables(options.out_dir, options.trials, summaries)
    _run_pool(pending, runs_dir, options.jobs, finish)
    return {
        "finished": len(summaries) - skipped,
        "skipped": skipped,
        "failed": failed,
        "wall_time_s": round(time.monotonic() - start, 1),
    }


def _run_pool(
    pending: list[Trial], runs_dir: Path, jobs: int, finish: Callable[[Trial, int], None]
) -> None:
    """Keep ``jobs`` runs going; on any exit (Ctrl-C included) stop the ones still running."""
    queue = list(pending)
    running: dict[Trial, subprocess.Popen] = {}
    mpc_helper = helper_has_a_core(jobs, os.cpu_count() or 1)
    previous = signal.signal(signal.SIGTERM, _raise_interrupt)
    try:
        while queue or running:
            while queue and len(running) < jobs:
                trial = queue.pop(0)
                running[trial] = _start_run(trial, runs_dir / trial.key, mpc_helper)
            for trial, process in list(running.items()):
                if process.poll() is not None:
                    del running[trial]
                    finish(trial, process.returncode)
            time.sleep(POLL_S)
    finally:
        signal.signal(signal.SIGTERM, previous)
        for process in running.values():
            process.terminate()
        for process in running.values():
            try:
                process.wait(timeout=15)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()


def helper_has_a_core(jobs: int, cores: int) -> bool:
    """Whether each of ``jobs`` parallel runs can give its ground station's MPC helper a core
    of its own (otherwise the helper only adds round trips)."""
    return 2 * jobs <= cores


def _raise_interrupt(*_: object) -> None:
    raise KeyboardInterrupt


def _start_run(trial: Trial, run_dir: Path, mpc_helper: bool) -> subprocess.Popen:
    if run_dir.exists():  # an unfinished run from an interrupted batch: start it afresh
        shutil.rmtree(run_dir)
    run_dir.mkdir(parents=True)
    command = [
        sys.executable,
        "-m",
        "mission",
        "run",
        trial.scenario,
        "--method",
        trial.method,
        "--seed",
        str(trial.seed),
        "--out",
        str(run_dir),
        "--mpc-helper" if mpc_helper else "--no-mpc-helper",
        "--exit-with-parent",
    ]
    with (run_dir / "mission.log").open("w") as log:
        return subprocess.Popen(
            command,
            stdout=log,
            stderr=log,
            stdin=subprocess.DEVNULL,
            env=child_environment(),
        )


def _one_line(summary: dict[str, Any]) -> str:
    done = (
        f"completed at {summary['completion_time_s']:.1f} s"
        if summary["completed"]
        else "NOT completed"
    )
    return (
        f"{done}, {summary['multipath_steps_total']} steps in multipath, "
        f"wall {summary['wall_time_s']:.1f} s"
    )


class ProgressBar:
    """``[#####.....] 12/60  mm:ss left  <last run>`` lines, one per finished run."""

    def __init__(self, total: int, done: int, stream: TextIO) -> None:
        self.total, self.done, self.stream = total, done, stream
        self.started, self.start_done = time.monotonic(), done
        self.stream.write(f"batch: {total} runs, {done} already finished\n")
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
