"""A short run and its recording, made once for the viewer's tests."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.processes import mission
from tests.runs.test_run import SHORT
from tests.viewer.rrd import read_rrd


@pytest.fixture(scope="session")
def short_run(tmp_path_factory) -> tuple[Path, Path]:
    """A short lockstep run: (its folder, its scenario file)."""
    folder = tmp_path_factory.mktemp("view")
    scenario = folder / "short-run.yaml"
    scenario.write_text(SHORT)
    assert mission("plan", str(scenario)).returncode == 0
    assert mission("run", str(scenario), "--out", str(folder / "run")).returncode == 0
    return folder / "run", scenario


@pytest.fixture(scope="session")
def replayed(short_run) -> tuple[Path, Path, dict]:
    """The short run's recording by ``mission view --save``: (run, scenario, rows)."""
    run, scenario = short_run
    result = mission("view", str(run), "--save", str(run.parent / "run.rrd"))
    assert result.returncode == 0, result.stderr
    return run, scenario, read_rrd(run.parent / "run.rrd")
