"""``mission view``'s bad input (one line, exit status 2, nothing written) and a run without
``--view`` never importing Rerun."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.processes import ROOT
from tests.viewer.conftest import mission

pytestmark = pytest.mark.slow  # starts Python processes


@pytest.mark.parametrize(
    ("make", "extra", "says"),
    [
        (lambda d: d / "missing", [], "no gcs.tlog here"),
        (lambda d: d, [], "no gcs.tlog here"),
        (lambda d: (d / "gcs.tlog").write_bytes(b"") or d, [], "no records.jsonl here"),
    ],
)
def test_a_folder_that_is_not_a_run_is_refused(tmp_path, make, extra, says):
    result = mission("view", str(make(tmp_path)), *extra)
    assert result.returncode == 2
    assert says in result.stderr and len(result.stderr.strip().splitlines()) == 1


def test_a_bad_save_path_is_refused_before_anything_is_written(short_run, tmp_path):
    run, _ = short_run
    for target, says in [
        (tmp_path / "view.txt", "must end in .rrd"),
        (tmp_path / "no-such-dir" / "view.rrd", "no directory"),
    ]:
        result = mission("view", str(run), "--save", str(target))
        assert result.returncode == 2 and says in result.stderr
        assert not target.exists()
    assert mission("view", str(run), "--scenario", "nowhere.yaml").returncode == 2


def test_a_run_without_view_does_not_import_rerun():
    code = (
        "import sys; from mission import cli; from mission.commands import run;"
        "from mission.runs import orchestrator;"
        "from mission.viewer import live, replay, feed;"
        "print('rerun' in sys.modules)"
    )
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True
    )
    assert result.stdout.strip() == "False"
