"""A run made as a user makes it, for the benchmarks that time whole runs."""

from __future__ import annotations

import subprocess
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

from mission.procs.command_line import FLOWN
from mission.procs.commands import mission_run_argv
from mission.procs.process_life import child_environment


def run_as_command(
    scenario: str, method: str, out: Path, mpc_helper: bool | None = None
) -> dict[str, Any]:
    """The summary of ``mission run SCENARIO --method METHOD --seed 0 --out OUT``, a fresh
    process (this one may have threads that keep it from forking vehicles)."""
    import json

    command = mission_run_argv(scenario, out, method, 0, mpc_helper, ["--exit-with-parent"])
    flown = subprocess.run(command, stdout=subprocess.DEVNULL, env=child_environment())
    if flown.returncode not in FLOWN:  # a run that timed out is a result: a missed target
        raise subprocess.CalledProcessError(flown.returncode, command)
    return json.loads((out / "summary.json").read_text())


def batch_wall_s(
    runs: Sequence[tuple[str, str]],
    out: Path,
    jobs: int,
    mpc_helper: bool | None,
    run: Callable[..., dict[str, Any]] = run_as_command,
) -> float:
    """Wall seconds of ``runs`` (scenario, method) made as ``mission batch`` makes them:
    ``jobs`` at a time, each a whole ``mission run`` (start-up and analysis included)."""
    started = time.monotonic()
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        made = [
            pool.submit(run, scenario, method, out / f"batch-{scenario}-{method}", mpc_helper)
            for scenario, method in runs
        ]
        for future in made:
            future.result()
    return time.monotonic() - started
