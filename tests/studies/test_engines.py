"""The engines with real runs: the local engine and a two-node Ray cluster on this machine
give the same results, spread over both nodes; a cancelled study leaves no process."""

from __future__ import annotations

import csv
import io
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import pytest

import mission.cli
from mission.studies.local_engine import LocalEngine
from mission.studies.spec import load_study
from mission.studies.study import run_study
from tests.extras import required
from tests.processes import ROOT

# what differs from run to run of the same lockstep mission: timings and where it ran
_TIMING = {"wall_time_s", "realtime_factor", "mpc_solve_ms.median", "mpc_solve_ms.p95", "node"}

SMALL_STUDY = """
name: small
scenarios: [along]
methods: [ac, nac]
seeds: 2
points:
  - {run.timeout_s: 15}
"""


def _rows(path: Path) -> dict[tuple[str, str], dict[str, str]]:
    return {(r["method"], r["seed"]): r for r in csv.DictReader(path.open())}


def _study(tmp_path: Path, text: str = SMALL_STUDY):
    path = tmp_path / "small.yaml"
    path.write_text(text)
    return load_study(path)


@pytest.mark.slow
def test_a_two_node_ray_cluster_gives_the_local_engines_results(tmp_path, capsys):
    ray = required("ray")
    from ray.cluster_utils import Cluster

    from mission.studies.ray_engine import RayEngine

    spec = _study(tmp_path)
    run_study(spec, tmp_path / "local", LocalEngine(2), progress=io.StringIO())
    cluster = Cluster(
        initialize_head=True,
        head_node_args={"num_cpus": 1, "include_dashboard": False},
    )
    cluster.add_node(num_cpus=1)
    try:
        ray.init(address=cluster.address, log_to_driver=False)
        outcome = run_study(
            spec, tmp_path / "ray", RayEngine(cluster.address, None), progress=io.StringIO()
        )
    finally:
        ray.shutdown()
        cluster.shutdown()
    assert outcome.failed == [] and outcome.finished == 4
    local, remote = (
        _rows(tmp_path / "local" / "results.csv"),
        _rows(tmp_path / "ray" / "results.csv"),
    )
    assert local.keys() == remote.keys()
    for key, row in local.items():
        same = {c: v for c, v in row.items() if c not in _TIMING}
        assert same == {c: v for c, v in remote[key].items() if c not in _TIMING}, key
    assert len({row["node"] for row in remote.values()}) == 2  # both nodes ran some
    run = next((tmp_path / "ray" / "runs").iterdir())  # the folder came back to the driver
    assert {"summary.json", "gcs.tlog", "records.jsonl", "scenario.yaml"} <= {
        p.name for p in run.iterdir()
    }
    # its summary names the node's (deleted) scenario file; analyze reads the one beside it
    summary = json.loads((run / "summary.json").read_text())
    assert not Path(summary["scenario_source"]).exists()
    assert mission.cli.entry_point(["analyze", str(run)]) == 0
    metrics = json.loads(capsys.readouterr().out)
    assert metrics == {k: summary[k] for k in metrics}


@pytest.mark.slow
@pytest.mark.parametrize("engine", ["local", "ray"])
def test_ctrl_c_cancels_a_study_and_leaves_no_process(tmp_path, engine):
    if engine == "ray":
        required("ray")
    path = tmp_path / "long.yaml"
    path.write_text(SMALL_STUDY.replace("run.timeout_s: 15", "run.timeout_s: 600"))
    marker = "mission-study-" if engine == "ray" else str(tmp_path)
    before = _ray_processes()
    study = subprocess.Popen(
        [sys.executable, "-m", "mission", "study", str(path), "--engine", engine,
         "--jobs", "2", "--out", str(tmp_path / "out")],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT,
        preexec_fn=_ignore_sigint,  # as a background job starts it: Ctrl-C must still work
    )  # fmt: skip
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and not _running(marker):
            time.sleep(0.2)
        assert _running(marker), "a run got going"
        time.sleep(1.0)
        study.send_signal(signal.SIGINT)
        stdout, stderr = study.communicate(timeout=90)
    finally:
        if study.poll() is None:
            study.kill()
    assert study.returncode == 130, stderr
    assert "run it again to resume" in stdout
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline and (_running(marker) or _ray_processes() > before):
        time.sleep(0.5)
    assert _running(marker) == [] and _ray_processes() <= before
    assert not list((tmp_path / "out").glob("runs/*/summary.json"))


def _ignore_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _running(marker: str) -> list[str]:
    """Processes of a run whose command line holds ``marker``."""
    found = subprocess.run(["pgrep", "-f", "--", marker], capture_output=True, text=True)
    return [p for p in found.stdout.split() if int(p) != os.getpid()]


def _ray_processes() -> int:
    found = subprocess.run(["pgrep", "-c", "-f", "raylet|gcs_server"], capture_output=True)
    return int(found.stdout.strip() or 0)


def test_a_local_rays_token_is_made_private_and_an_old_ray_is_refused(monkeypatch, tmp_path):
    ray = required("ray")
    from mission.config.errors import InputError
    from mission.studies.ray_engine import keep_token_private, require_ray

    token = tmp_path / ".ray" / "auth_token"
    token.parent.mkdir()
    token.write_text("secret")
    token.chmod(0o644)  # as Ray writes it
    keep_token_private(tmp_path)
    assert token.stat().st_mode & 0o777 == 0o600
    keep_token_private(tmp_path / "nobody")  # no token: nothing to do
    monkeypatch.setattr(ray, "__version__", "2.58.1")
    with pytest.raises(InputError, match=r"Ray 2\.58\.1: the Ray engine needs Ray 2\.59 or later"):
        require_ray()


def test_a_failed_ray_task_leaves_its_reason_where_the_progress_line_points(tmp_path):
    from mission.studies.ray_engine import FAILURE_FILE, _collect

    class _Ray:
        @staticmethod
        def get(ref):
            raise RuntimeError("the worker died: out of memory")

    run = SimpleNamespace(folder="along-ac-0-abc")
    reported = []
    _collect(_Ray(), None, run, tmp_path, lambda *args: reported.append(args))
    assert reported == [(run, None, 0.0)]
    reason = (tmp_path / "along-ac-0-abc" / FAILURE_FILE).read_text()
    assert reason == "RuntimeError: the worker died: out of memory\n"
