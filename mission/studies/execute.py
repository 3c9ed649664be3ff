"""One study run in its folder, the same on every engine: the resolved scenario written as
``scenario.yaml``, ``python -m mission run`` on it, and the study's own block added to its
``summary.json``. A run's folder travels to the driver as a gzipped tar (Ray engine).
"""

from __future__ import annotations

import io
import json
import shutil
import socket
import subprocess
import tarfile
from pathlib import Path
from typing import Any, Literal, get_args

import yaml

from mission.config.scenario import resolved_mapping
from mission.procs.atomic import write_text_atomically
from mission.procs.command_line import FLOWN
from mission.procs.commands import mission_run_argv
from mission.procs.process_life import child_environment
from mission.studies.runkeys import StudyRun

Keep = Literal["all", "logs", "summary"]
KEEP_CHOICES: tuple[Keep, ...] = get_args(Keep)
SCENARIO_FILE = "scenario.yaml"


def prepare(run: StudyRun, run_dir: Path) -> None:
    """A fresh folder holding the run's resolved scenario (resolved on this machine)."""
    if run_dir.exists():  # an unfinished run of an interrupted study: start it afresh
        shutil.rmtree(run_dir)
    run_dir.mkdir(parents=True)
    mapping = resolved_mapping(run.scenario, run.overrides)
    (run_dir / SCENARIO_FILE).write_text(yaml.safe_dump(mapping, sort_keys=False))


def start(run: StudyRun, run_dir: Path, mpc_helper: bool, keep: Keep = "all") -> subprocess.Popen:
    """``mission run`` of the prepared folder, its output in ``mission.log``; it dies with
    this process. A study that keeps no G snapshots (``keep`` logs or summary) has its runs
    write none."""
    extra = ["--exit-with-parent"]
    if keep != "all":
        extra += ["--g-snapshots", "none"]
    command = mission_run_argv(
        run_dir / SCENARIO_FILE, run_dir, run.method, run.seed, mpc_helper, extra
    )
    if run.speedup is not None:
        command += ["--realtime", "--speedup", str(run.speedup)]
    with (run_dir / "mission.log").open("w") as log:
        return subprocess.Popen(
            command, stdout=log, stderr=log, stdin=subprocess.DEVNULL, env=child_environment()
        )


def conclude(run: StudyRun, run_dir: Path, status: int, node: str, keep: Keep) -> dict | None:
    """The finished run's summary with the study's block added (also in its summary.json),
    or None if it failed; files beyond ``keep`` are removed."""
    summary = _read_summary(run_dir)
    if status not in FLOWN or summary is None or not exact(summary):
        return None
    summary["study"] = {
        "run_key": run.key,
        "point": run.point,
        "overrides": run.overrides,
        "node": node,
    }
    write_text_atomically(run_dir / "summary.json", json.dumps(summary, indent=2) + "\n")
    trim(run_dir, keep)
    return summary


def finished_summary(run: StudyRun, run_dir: Path) -> dict | None:
    """The summary of a run this study already finished (same key), else None."""
    summary = _read_summary(run_dir)
    if summary is None or (summary.get("study") or {}).get("run_key") != run.key:
        return None
    return summary if exact(summary) else None


def exact(summary: dict[str, Any]) -> bool:
    """Whether a run kept its lockstep (no wall-clock timeout fired:
    :mod:`mission.analysis.lockstep`), so that it reproduces; a real-time run has no
    such block. A study counts a run that did not as failed, and makes it again."""
    lockstep = summary.get("lockstep")
    return not isinstance(lockstep, dict) or lockstep.get("exact", True) is not False


def trim(run_dir: Path, keep: Keep) -> None:
    """Keep everything, or drop G's snapshots (``logs``), or all but the summary and the
    scenario (``summary``)."""
    if keep == "all":
        return
    for path in run_dir.iterdir():
        wanted = path.name in ("summary.json", SCENARIO_FILE) or (
            keep == "logs" and path.name != "g"
        )
        if not wanted:
            shutil.rmtree(path) if path.is_dir() else path.unlink()


def pack(run_dir: Path) -> bytes:
    """The folder as a gzipped tar, paths relative to it."""
    buffer = io.BytesIO()
    with tarfile.open(fileobj=buffer, mode="w:gz", compresslevel=3) as tar:
        for path in sorted(run_dir.rglob("*")):
            tar.add(path, arcname=str(path.relative_to(run_dir)), recursive=False)
    return buffer.getvalue()


def unpack(data: bytes, run_dir: Path) -> None:
    """A packed folder into ``run_dir`` (replacing what is there)."""
    if run_dir.exists():
        shutil.rmtree(run_dir)
    run_dir.mkdir(parents=True)
    with tarfile.open(fileobj=io.BytesIO(data), mode="r:gz") as tar:
        tar.extractall(run_dir, filter="data")


def this_node() -> str:
    """The name of the machine a run ran on."""
    return socket.gethostname()


def _read_summary(run_dir: Path) -> dict[str, Any] | None:
    try:
        summary = json.loads((run_dir / "summary.json").read_text())
    except (OSError, ValueError):
        return None
    return summary if isinstance(summary, dict) else None
