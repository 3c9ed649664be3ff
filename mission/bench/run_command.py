"""A run made as a user makes it, for the benchmarks that time whole runs."""

from __future__ import annotations

import subprocess
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
