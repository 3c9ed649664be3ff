"""Lockstep decides the same whatever the load, and says when it could not: the short run
made again while two busy loops hold both cores gives the same decisions and summary; a
vehicle frozen for longer than the lockstep's wall-clock timeouts makes the run say it is not
exact."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from mission.studies.verify import is_timing
from tests.processes import ROOT, mission, stop_process, vehicle_pids

pytestmark = pytest.mark.slow  # every test here starts runs

BUSY_LOOP = "while True:\n    pass\n"
# what differs between two runs of one lockstep mission: the machine's figures
_MACHINE = {"wall_time_s", "realtime_factor", "cpu_s", "compile_s", "compiled", "link"}
_MACHINE |= {"provenance"}


def _decided(summary: dict) -> dict:
    return {
        key: value
        for key, value in summary.items()
        if key not in _MACHINE
        and not is_timing(key)
        and key not in ("mpc_solve_ms",)
        and key != "scenario_source"
    }


def test_a_run_on_a_loaded_machine_decides_as_on_an_idle_one(short_run, tmp_path):
    run_dir, scenario = short_run
    busy = [subprocess.Popen([sys.executable, "-c", BUSY_LOOP]) for _ in range(2)]
    try:
        result = mission("run", str(scenario), "--out", str(tmp_path / "loaded"))
    finally:
        for process in busy:
            stop_process(process)
    assert result.returncode == 0, result.stderr
    idle = json.loads((run_dir / "summary.json").read_text())
    loaded = json.loads((tmp_path / "loaded" / "summary.json").read_text())
    assert loaded["decisions_digest"] == idle["decisions_digest"]
    assert _decided(loaded) == _decided(idle)
    assert loaded["lockstep"] == {
        "exact": True,
        "auto_steps": 0,
        "truth_waits_timed_out": 0,
        "late_steps": 0,
    }


def test_a_vehicle_frozen_past_the_timeouts_makes_the_run_say_it_is_not_exact(short_run, tmp_path):
    _, short = short_run
    scenario = tmp_path / "impatient.yaml"  # vehicles that step alone after 1 s, not 10
    scenario.write_text(f"extends: {short}\nvehicle: {{lockstep_timeout_wall_s: 1.0}}\n")
    out = tmp_path / "frozen"
    command = [sys.executable, "-m", "mission", "run", str(scenario), "--out", str(out)]
    run = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.PIPE, text=True)
    try:
        pids = _wait_for_vehicle(run.pid, "support-2")
        _wait_for_cycles(out / "records.jsonl", 5)
        for pid in pids:
            _signal(pid, signal.SIGSTOP)
        time.sleep(3.0)  # > lockstep_timeout_wall_s: the others step alone
        for pid in pids:
            _signal(pid, signal.SIGCONT)
        output, _ = run.communicate(timeout=300)
    finally:
        stop_process(run)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["lockstep"]["exact"] is False
    assert summary["lockstep"]["auto_steps"] > 0
    assert "NOT exact lockstep (auto steps" in output


def _signal(pid: int, number: int) -> None:
    with contextlib.suppress(ProcessLookupError):  # it ended meanwhile
        os.kill(pid, number)


def _wait_for_vehicle(parent: int, name: str) -> list[int]:
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        pids = vehicle_pids(parent, name)
        if pids:
            return pids
        time.sleep(0.05)
    raise AssertionError(f"{name} did not start")


def _wait_for_cycles(records: Path, cycles: int) -> None:
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        if records.is_file() and len(records.read_text().splitlines()) >= cycles:
            return
        time.sleep(0.02)
    raise AssertionError("the run made no cycles")
