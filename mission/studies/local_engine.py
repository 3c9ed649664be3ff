"""The local engine: up to ``jobs`` runs at once as child processes of this one."""

from __future__ import annotations

import os
import subprocess
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from mission.procs.interrupts import StopRequest
from mission.procs.stopping import stop_processes
from mission.studies.execute import Keep, conclude, prepare, start, this_node
from mission.studies.runkeys import StudyRun

POLL_S = 0.1
Done = Callable[[StudyRun, "dict | None", float], None]  # run, summary (None: failed), wall s


def helper_has_a_core(jobs: int, cores: int) -> bool:
    """Whether each of ``jobs`` parallel runs can give its ground station's MPC helper a core
    of its own (otherwise the helper only adds round trips)."""
    return 2 * jobs <= cores


@dataclass(frozen=True)
class LocalEngine:
    """Runs on this machine, ``jobs`` at a time."""

    jobs: int

    @property
    def cores(self) -> int:
        """How many runs go at once."""
        return self.jobs

    @property
    def description(self) -> str:
        """What the progress line says of the engine."""
        return f"local engine, {self.jobs} at a time"

    def run(self, runs: list[StudyRun], runs_dir: Path, keep: Keep, done: Done) -> None:
        """Run every one of ``runs``; on any exit (Ctrl-C included) stop those still going."""
        queue = list(runs)
        running: dict[StudyRun, tuple[subprocess.Popen, float]] = {}
        mpc_helper = helper_has_a_core(self.jobs, os.cpu_count() or 1)
        node = this_node()
        with StopRequest() as stop:
            try:
                while queue or running:
                    stop.check()  # a request whose exception was swallowed (in a fork)
                    while queue and len(running) < self.jobs:
                        run = queue.pop(0)
                        prepare(run, runs_dir / run.folder)
                        process = start(run, runs_dir / run.folder, mpc_helper, keep)
                        running[run] = (process, time.monotonic())
                    for run, (process, started) in list(running.items()):
                        if process.poll() is None:
                            continue
                        del running[run]
                        wall = time.monotonic() - started
                        status = process.returncode
                        done(run, conclude(run, runs_dir / run.folder, status, node, keep), wall)
                    time.sleep(POLL_S)
            finally:
                stop_processes((process for process, _ in running.values()), grace_s=15.0)
