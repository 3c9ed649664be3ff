"""Faults during a run: a support vehicle killed and restarted, the ground station killed."""

from __future__ import annotations

import json
import re
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from mission.analysis.metrics import read_tlog
from mission.config.scenario import load_scenario
from tests.processes import ROOT, stop_process, vehicle_pids

pytestmark = pytest.mark.slow  # every test here starts processes

FAULT_SCENARIO = "extends: along\nname: fault-run\n"
BANNER = re.compile(r"listening on [\d.]+:(\d+), truth port (\d+)")


@pytest.fixture
def scenario(tmp_path) -> Path:
    path = tmp_path / "fault-run.yaml"
    path.write_text(FAULT_SCENARIO)
    return path


def _start_run(scenario: Path, out: Path, *extra: str) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "mission", "run", str(scenario), "--out", str(out), *extra],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )


def _cycles(out: Path) -> int:
    try:
        return sum(1 for _ in (out / "records.jsonl").open())
    except OSError:
        return 0


def _wait_cycles(out: Path, cycles: int, timeout_s: float = 120.0) -> None:
    deadline = time.monotonic() + timeout_s
    while _cycles(out) < cycles:
        assert time.monotonic() < deadline, f"the run did not reach cycle {cycles}"
        time.sleep(0.05)


def _pids(pattern: str) -> list[str]:
    return subprocess.run(
        ["pgrep", "-f", "--", pattern], capture_output=True, text=True
    ).stdout.split()


def _children(parent: int, name: str) -> list[str]:
    return subprocess.run(
        ["pgrep", "-P", str(parent), "-x", name], capture_output=True, text=True
    ).stdout.split()


def test_a_killed_support_is_dropped_then_taken_back(scenario, tmp_path):
    out = tmp_path / "run"
    run = _start_run(scenario, out)
    restarted = None
    try:
        _wait_cycles(out, 60)
        port, truth_port = BANNER.search((out / "support-2.log").read_text()).groups()
        victim = vehicle_pids(run.pid, "support-2")
        assert len(victim) == 1
        subprocess.run(["kill", "-9", str(victim[0])], check=True)
        killed_at = _cycles(out)
        _wait_cycles(out, killed_at + 20)  # lost after 3 s = 6 cycles; let it run without
        restarted = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "vehicle_sim",
                "--vehicle",
                "support-2",
                "--scenario",
                str(scenario),
                "--port",
                port,
                "--truth-port",
                truth_port,
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            cwd=ROOT,
        )
        _, stderr = run.communicate(timeout=300)
    finally:
        if run.poll() is None:
            run.kill()
        if restarted is not None:
            stop_process(restarted)
    assert run.returncode == 0, stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["completed"] is True
    events = [(e["t"], e["event"].split(":")[0]) for e in summary["link_events"]]
    assert [e for _, e in events] == ["support-2 lost", "support-2 back"], events
    trace = read_tlog(out / "gcs.tlog", load_scenario(str(scenario)))
    times, _ = trace.track(3)
    last_heard = max(t for t in times if t < events[0][0])
    assert events[0][0] - last_heard <= 3.0 + 0.5  # noticed within 3 s of simulated time
    records = [json.loads(line) for line in (out / "records.jsonl").open()]
    away = [r for r in records if events[0][0] <= r["t"] < events[1][0]]
    assert away and all("support-2" not in r["mpc"] for r in away)
    assert all(set(r["mpc"]) == {"support-1", "support-3"} for r in away)
    after = [r for r in records if r["t"] > events[1][0] + 5]
    assert any("support-2" in r["contributing"] for r in after), "fused again once back"
    assert _pids(str(scenario)) == []


def test_a_killed_ground_station_ends_the_run_naming_it_with_the_tlog_readable(scenario, tmp_path):
    out = tmp_path / "run"
    run = _start_run(scenario, out, "--mpc-helper")
    try:
        _wait_cycles(out, 40)
        gcs = _children(run.pid, "ground_station")
        assert len(gcs) == 1
        helper = _children(int(gcs[0]), "gcs-mpc-helper")
        assert len(helper) == 1
        # both forked (each parent had one thread): they have the run's command line
        commands = {Path(f"/proc/{pid}/cmdline").read_bytes() for pid in (run.pid, *gcs, *helper)}
        assert len(commands) == 1
        subprocess.run(["kill", "-9", *gcs], check=True)
        _, stderr = run.communicate(timeout=120)
    finally:
        if run.poll() is None:
            run.send_signal(signal.SIGKILL)
    assert run.returncode == 1
    assert "ground_station exited with status -9" in stderr and "logs kept" in stderr
    trace = read_tlog(out / "gcs.tlog", load_scenario(str(scenario)))
    assert len(trace.ticks) >= 40  # every flushed cycle is there and parses
    assert _pids(str(scenario)) == []
    deadline = time.monotonic() + 10  # the helper ends at the end of its input
    while Path(f"/proc/{helper[0]}").exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not Path(f"/proc/{helper[0]}").exists()


def test_the_ground_station_survives_fuzzing_during_upload_and_run(scenario, tmp_path):
    from tests.fuzzing import hostile_datagrams

    datagrams = hostile_datagrams(seed=2)
    assert len(datagrams) >= 10_000
    out = tmp_path / "run"
    run = _start_run(scenario, out)
    try:
        deadline = time.monotonic() + 60
        found = None
        while found is None and time.monotonic() < deadline:
            log = out / "ground_station.log"
            found = (
                re.search(r"ground station listening on ([\d.]+):(\d+)", log.read_text())
                if log.exists()
                else None
            )
            time.sleep(0.02)
        assert found, "the ground station started"
        address = (found.group(1), int(found.group(2)))
        fuzzer = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        for i, datagram in enumerate(datagrams):  # while it connects, uploads and flies
            fuzzer.sendto(datagram, address)
            if i % 100 == 99:  # spread over ~2 s: a burst overflows the socket's buffer
                time.sleep(0.02)
        fuzzer.close()
        _, stderr = run.communicate(timeout=300)
    finally:
        if run.poll() is None:
            run.kill()
    assert run.returncode == 0, stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["completed"] is True
    assert summary["link"]["rejected"]["unknown sender"] >= 3000
    assert "Traceback" not in (out / "ground_station.log").read_text()
    trace = read_tlog(out / "gcs.tlog", load_scenario(str(scenario)))
    assert {s for s, _ in trace.truth} == {1, 2, 3, 4}  # nothing forged reached the log


@pytest.mark.parametrize("parent_is_named", [True, False])
def test_a_child_whose_named_parent_is_gone_stops_itself(parent_is_named):
    """die_with_parent: prctl cannot cover a parent that died before the child called it, so
    the child compares its parent with the one named in MISSION_PARENT_PID and stops."""
    import os

    from mission.procs.process_life import PARENT_PID_VARIABLE

    code = (
        "from mission.procs.process_life import die_with_parent; die_with_parent(); print('alive')"
    )
    named = os.getpid() if parent_is_named else 1  # pid 1 is never this child's parent here
    env = {**os.environ, PARENT_PID_VARIABLE: str(named)}
    child = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=60
    )
    if parent_is_named:
        assert (child.returncode, child.stdout) == (0, "alive\n")
    else:
        assert (child.returncode, child.stdout) == (-signal.SIGTERM, "")


def test_a_silent_work_uav_ends_the_run_from_the_ground_station(scenario, tmp_path):
    """A frozen (not dead) work vehicle: the orchestrator sees no exit, so the ground station
    must notice the silence itself (3 s of simulated time) and end the run naming it."""
    out = tmp_path / "run"
    run = _start_run(scenario, out)
    work: list[str] = []
    try:
        _wait_cycles(out, 40)
        work = [str(pid) for pid in vehicle_pids(run.pid, "work")]
        assert len(work) == 1
        subprocess.run(["kill", "-STOP", *work], check=True)
        _, stderr = run.communicate(timeout=120)
    finally:
        if work:
            subprocess.run(["kill", "-CONT", *work], capture_output=True)
        if run.poll() is None:
            run.send_signal(signal.SIGKILL)
    assert run.returncode == 1
    assert "ground_station exited with status 1: work lost: no message for 3.0 s" in stderr
    assert "work lost: no message for 3.0 s" in (out / "ground_station.log").read_text()
    summary = json.loads((out / "summary.json").read_text())  # what it got to, and why not on
    assert "work lost: no message for 3.0 s" in summary["failed"]
    assert not summary["completed"] and summary["control_cycles"] >= 40
    trace = read_tlog(out / "gcs.tlog", load_scenario(str(scenario)))
    assert len(trace.ticks) >= 40
    assert _pids(str(scenario)) == []
