"""A scenario's ``faults:`` in a whole run: applied by each vehicle at the step boundary of its
time, the same in every run of the seed, said in the tlog and listed in summary.json's events
with a parameter set from an outside ground station mid-run."""

from __future__ import annotations

import json
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from tests.mav_client import MavClient
from tests.processes import EXIT_NOT_COMPLETED, ROOT, mission
from tests.runs.test_run import _records

pytestmark = pytest.mark.slow  # whole runs

SCENARIO = """extends: along
name: scripted-faults
run:
  timeout_s: {timeout}
faults:
  - {{at_s: 10, vehicle: support-1, failure: gps off, duration_s: 10}}
  - {{at_s: 20, vehicle: support-3, failure: camera off}}
"""
BANNER = re.compile(r"listening on [\d.]+:(\d+)")


def _scenario(tmp_path: Path, timeout_s: float) -> Path:
    path = tmp_path / f"scripted-faults-{timeout_s:g}.yaml"
    path.write_text(SCENARIO.format(timeout=timeout_s))
    return path


@pytest.fixture(scope="module")
def twice(tmp_path_factory) -> tuple[Path, Path]:
    """The same scenario and seed run twice."""
    tmp = tmp_path_factory.mktemp("faults")
    scenario = _scenario(tmp, 40)
    outs = tmp / "a", tmp / "b"
    for out in outs:
        result = mission("run", str(scenario), "--out", str(out))
        assert result.returncode == EXIT_NOT_COMPLETED, result.stderr
    return outs


def test_scripted_faults_happen_at_their_step_and_are_listed(twice):
    summary = json.loads((twice[0] / "summary.json").read_text())
    assert summary["events"] == [
        {"t": 10.0, "vehicle": "support-1", "source": "scenario", "event": "gps off"},
        {"t": 20.0, "vehicle": "support-1", "source": "scenario", "event": "gps ok"},
        {"t": 20.0, "vehicle": "support-3", "source": "scenario", "event": "camera off"},
    ]
    records = [json.loads(line) for line in (twice[0] / "records.jsonl").open()]
    without_gnss = [r for r in records if 10.0 <= r["t"] < 20.0]
    assert len(without_gnss) == 20
    assert all("support-1" not in r["contributing"] for r in without_gnss)
    assert all(r["beta"]["support-1"] is None for r in without_gnss)
    back = [r for r in records if 20.0 <= r["t"] < 25.0]
    assert any("support-1" in r["contributing"] for r in back)
    assert all("support-3" not in r["contributing"] for r in records if r["t"] >= 20.0)


def test_a_run_with_faults_is_the_same_every_time(twice):
    assert _records(twice[0]) == _records(twice[1])


def test_a_parameter_set_from_outside_mid_run_is_applied_and_listed(tmp_path):
    out = tmp_path / "run"
    run = subprocess.Popen(
        [sys.executable, "-m", "mission", "run", str(_scenario(tmp_path, 60)), "--out", str(out)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    try:
        deadline = time.monotonic() + 60
        while sum(1 for _ in _lines(out / "records.jsonl")) < 30:
            assert time.monotonic() < deadline and run.poll() is None, "the run did not start"
            time.sleep(0.02)
        port = int(BANNER.search((out / "support-2.log").read_text()).group(1))
        client = MavClient(("127.0.0.1", port))
        try:
            client.send(
                mavlink2.MAVLink_param_set_message(
                    3, 1, b"SIM_CAM_NOISE", 2.0, mavlink2.MAV_PARAM_TYPE_REAL32
                )
            )
            echo = client.wait_for("PARAM_VALUE", where=lambda m: m.param_id == "SIM_CAM_NOISE")
        finally:
            client.close()
        assert echo is not None and echo.param_value == 2.0
        _, stderr = run.communicate(timeout=120)
    finally:
        if run.poll() is None:
            run.kill()
            run.wait()
    assert run.returncode == EXIT_NOT_COMPLETED, stderr
    events = json.loads((out / "summary.json").read_text())["events"]
    sets = [e for e in events if e["source"] == "parameter"]
    assert len(sets) == 1 and sets[0]["vehicle"] == "support-2"
    assert sets[0]["event"] == "SIM_CAM_NOISE=2" and 15.0 <= sets[0]["t"] < 60.0
    with (out / "gcs.tlog").open("rb") as tlog:
        assert f"Set SIM_CAM_NOISE=2 t={sets[0]['t']:.2f}".encode() in tlog.read()


def _lines(path: Path) -> list[str]:
    try:
        return path.read_text().splitlines()
    except OSError:
        return []


LOSSY_FAULTS = """extends: along
name: lossy-faults
run:
  timeout_s: 10
faults:
{faults}
  - {{at_s: 8, vehicle: work, param: SIM_LINK_LOSS, value: 0.9}}
"""


def test_a_lossy_link_loses_no_event(tmp_path):
    """Ten parameter faults (twenty events) and the work UAV's own link made to lose 90 %:
    over a link losing 30 % each way the summary lists every event the lossless run does (an
    event leaves in its step's marker datagram, which is asked for again until it arrives)."""
    faults = "\n".join(
        f"  - {{at_s: {at}, vehicle: {vehicle}, param: {param}, value: {at % 3 + 2}, "
        "duration_s: 0.5}"
        for vehicle, param in (("support-1", "SIM_MP_SCALE"), ("support-2", "SIM_CAM_NOISE"))
        for at in (2, 3, 4, 5, 6)
    )
    scenario = tmp_path / "lossy-faults.yaml"
    scenario.write_text(LOSSY_FAULTS.format(faults=faults))
    summaries = []
    for name, flags in (("clean", []), ("lossy", ["--link-loss", "0.3"])):
        result = mission("run", str(scenario), "--out", str(tmp_path / name), *flags)
        assert result.returncode == EXIT_NOT_COMPLETED, result.stderr
        summaries.append(json.loads((tmp_path / name / "summary.json").read_text()))
    clean, lossy = summaries
    assert len(clean["events"]) == 21
    assert clean["events"][-1] == {
        "t": 8.0,
        "vehicle": "work",
        "source": "scenario",
        "event": "SIM_LINK_LOSS=0.9",
    }
    assert lossy["link"]["dropped_out"] > 0
    assert lossy["events"] == clean["events"]
    assert lossy["decisions_digest"] == clean["decisions_digest"]
