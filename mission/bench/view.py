"""The live 3-D view's cost: how much ``mission run --view web`` slows a lockstep run."""

from __future__ import annotations

import json
import signal
import statistics
import subprocess
import tempfile
from pathlib import Path

from mission.bench.result import BenchResult
from mission.procs.command_line import FLOWN
from mission.procs.commands import mission_run_argv
from mission.procs.process_life import child_environment

MAX_SLOWDOWN = 0.10  # the bound: at most 10 % slower with the live view


def bench_view(repeats: int = 5) -> list[BenchResult]:
    """Along AC seed 0, ``repeats`` times each with and without ``--view web`` (alternating,
    so a drift of the machine's speed hits both alike): the medians of the runs' own wall
    times (summary.json, which includes the view's last rows) and the slowdown. The viewer
    serves the web page with no browser attached: what a browser draws is the browser's."""
    plain, viewed = [], []
    with tempfile.TemporaryDirectory(prefix="bench-view-") as temp:
        for repeat in range(repeats):
            plain.append(_wall(Path(temp) / f"plain-{repeat}", view=False))
            viewed.append(_wall(Path(temp) / f"view-{repeat}", view=True))
    without, with_view = statistics.median(plain), statistics.median(viewed)
    slowdown = with_view / without - 1.0
    return [
        BenchResult("run_wall_s_without_view", without, "s", "reference", None),
        BenchResult("run_wall_s_with_live_view", with_view, "s", "reference", None),
        BenchResult("live_view_slowdown", 100 * slowdown, "%", "<= 10", slowdown <= MAX_SLOWDOWN),
    ]


def _wall(out: Path, view: bool) -> float:
    """The wall time of one run; with the view, the viewer is stopped (Ctrl-C) once the run
    is over and it says so."""
    command = mission_run_argv("along", out, extra=["--exit-with-parent"])  # a killed bench
    if not view:
        flown = subprocess.run(command, stdout=subprocess.DEVNULL, env=child_environment())
        if flown.returncode not in FLOWN:  # a run that timed out still took its wall time
            raise subprocess.CalledProcessError(flown.returncode, command)
        return json.loads((out / "summary.json").read_text())["wall_time_s"]
    process = subprocess.Popen(
        [*command, "--view", "web"], stdout=subprocess.PIPE, text=True, env=child_environment()
    )
    try:
        for line in process.stdout:  # the run is over when it says where the viewer stays
            if line.startswith("viewer at "):
                break
        else:
            raise RuntimeError(f"mission run --view exited with {process.wait()}")
    finally:
        process.send_signal(signal.SIGINT)
        process.wait(timeout=60)
    return json.loads((out / "summary.json").read_text())["wall_time_s"]
