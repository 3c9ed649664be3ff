"""The short run's recording, made once for the viewer's tests (the run: ``short_run``)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.processes import mission
from tests.viewer.rrd import read_rrd


@pytest.fixture(scope="session")
def replayed(short_run, tmp_path_factory) -> tuple[Path, Path, dict]:
    """The short run's recording by ``mission view --save`` (beside, not in, the shared
    run's folder): (run, scenario, rows)."""
    run, scenario = short_run
    recording = tmp_path_factory.mktemp("replay") / "run.rrd"
    result = mission("view", str(run), "--save", str(recording))
    assert result.returncode == 0, result.stderr
    return run, scenario, read_rrd(recording)
