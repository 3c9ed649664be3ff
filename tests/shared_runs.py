"""Runs several test modules read: the short mission's scenario, and the runs made once per
session (by the fixtures of ``tests/conftest.py``). A test reads these folders and never
changes them."""

from __future__ import annotations

from pathlib import Path

from tests.processes import mission

SHORT = """
extends: along
name: short-run
task:
  work_waypoints_m: [[-6.0, -3.0, 7.0], [-3.0, -3.0, 7.0], [0.0, -3.0, 7.0]]
  waypoints_dir: plan
run: {timeout_s: 120.0}
world:
  zones:
    - {name: test, min_m: [-14.0, -12.0, 5.0], max_m: [-4.0, -6.0, 11.0], offset_m: [1.0, 0, 0]}
"""


def short_lockstep_run(folder: Path) -> tuple[Path, Path]:
    """The short mission planned and run in lockstep with seed 0 under ``folder``: (its run
    folder, its scenario file)."""
    scenario = folder / "short-run.yaml"
    scenario.write_text(SHORT)
    assert mission("plan", str(scenario)).returncode == 0
    result = mission("run", str(scenario), "--out", str(folder / "run"))
    assert result.returncode == 0, result.stderr
    return folder / "run", scenario


def along_lockstep_run(folder: Path) -> Path:
    """``mission run along`` with the defaults (AC, seed 0, lockstep) into ``folder``/run."""
    result = mission("run", "along", "--out", str(folder / "run"))
    assert result.returncode == 0, result.stderr
    return folder / "run"
