"""``mission run --out`` into a folder that holds a run: refused (a bad-input case), or with
``--force`` the earlier run's files removed first and the new run written whole."""

from __future__ import annotations

import json
import shutil

import pytest

from tests.processes import mission

pytestmark = pytest.mark.slow  # a whole run


def test_force_writes_over_an_earlier_run_and_keeps_nothing_of_it(short_run, tmp_path):
    earlier, scenario = short_run
    out = tmp_path / "run"
    shutil.copytree(earlier, out)
    (out / "plots").mkdir(exist_ok=True)
    (out / "plots" / "old.png").write_bytes(b"old")
    (out / "support-7.log").write_text("a support this scenario does not have\n")
    (out / "notes.txt").write_text("the user's, not the run's\n")
    refused = mission("run", str(scenario), "--out", str(out))
    assert refused.returncode == 2 and "holds a run" in refused.stderr
    result = mission("run", str(scenario), "--out", str(out), "--force")
    assert result.returncode == 0, result.stderr
    assert not (out / "plots").exists() and not (out / "support-7.log").exists()
    assert (out / "notes.txt").exists()
    summary = json.loads((out / "summary.json").read_text())
    assert (
        summary["decisions_digest"]
        == json.loads((earlier / "summary.json").read_text())["decisions_digest"]
    )
