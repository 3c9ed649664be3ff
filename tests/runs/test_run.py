"""``mission run``: a short mission end to end, teardown, failure of a vehicle, determinism."""

from __future__ import annotations

import contextlib
import json
import os
import re
import resource
import shutil
import signal
import struct
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from tests.processes import ROOT, vehicle_pids
from tests.shared_runs import SHORT

pytestmark = pytest.mark.slow  # every test here starts processes

VOLATILE = {
    "wall_time_s",
    "realtime_factor",
    "mpc_solve_ms",
    "cpu_s",
    "provenance",
}  # the machine's
LINK_TIMING = {"tick_resends", "late_steps"}  # how often a step was slow: wall-clock too


def _steady(summary: dict) -> dict:
    """The summary without its wall-clock figures."""
    steady = {k: v for k, v in summary.items() if k not in VOLATILE}
    if "link" in steady:
        steady["link"] = {k: v for k, v in steady["link"].items() if k not in LINK_TIMING}
    return steady


@pytest.fixture(scope="module")
def scenario(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("run") / "short-run.yaml"
    path.write_text(SHORT)
    subprocess.run(
        [sys.executable, "-m", "mission", "plan", str(path)],
        check=True,
        capture_output=True,
        timeout=300,
        cwd=ROOT,
    )
    return path


def _children_of(scenario: Path) -> list[str]:
    found = subprocess.run(["pgrep", "-f", "--", str(scenario)], capture_output=True, text=True)
    return found.stdout.split()


def _processes_of(out: Path) -> list[str]:
    """Processes whose command line names the run's directory: forked, the ground station,
    its MPC helper and the vehicles have the run's."""
    found = subprocess.run(["pgrep", "-f", "--", str(out)], capture_output=True, text=True)
    return found.stdout.split()


def _run(scenario: Path, out: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "mission", "run", str(scenario), "--out", str(out), *extra],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=ROOT,
    )


def _analyze(run: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "mission", "analyze", str(run), *extra],
        capture_output=True, text=True, timeout=300, cwd=ROOT,
    )  # fmt: skip


def _analysis_keeps_a_summary_its_tlog_cannot_hold(run: Path, copy: Path) -> None:
    """A copy of a finished run whose tlog was cut short, and one whose figures cannot be
    written: each refused on one line, its summary.json byte for byte as it was."""
    shutil.copytree(run, copy)
    summary = (copy / "summary.json").read_bytes()
    (copy / "plots" / "error.png").unlink()
    (copy / "plots" / "error.png").mkdir()
    refused = _analyze(copy, "--plots")
    assert refused.returncode == 2 and "error.png is a directory" in refused.stderr
    tlog = (copy / "gcs.tlog").read_bytes()
    (copy / "gcs.tlog").write_bytes(tlog[: len(tlog) * 2 // 5])
    refused = _analyze(copy)
    assert refused.returncode == 2, refused.stderr
    assert len(refused.stderr.strip().splitlines()) == 1
    assert "cut short? summary.json is not rewritten" in refused.stderr
    assert (copy / "summary.json").read_bytes() == summary


def test_run_completes_writes_a_summary_and_leaves_no_process(scenario, tmp_path):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    result = _run(scenario, tmp_path / "a", "--seed", "2", "--mpc-helper")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    assert result.returncode == 0, result.stderr
    assert "completed at" in result.stdout
    summary = json.loads((tmp_path / "a" / "summary.json").read_text())
    assert summary["completed"] is True and summary["method"] == "ac" and summary["seed"] == 2
    assert 10 < summary["completion_time_s"] < 120
    assert summary["control_cycles"] == round(summary["completion_time_s"] / 0.5)
    assert set(summary["multipath_steps"]) == {"support-1", "support-2", "support-3"}
    assert summary["multipath_steps_total"] == sum(summary["multipath_steps"].values())
    assert 0 < summary["work_error_m"]["mean"] < 1.0
    # a kinematic point reaches what the ideal vehicle of the tracking error reaches
    assert summary["tracking_error_m"]["work"]["max"] < 1e-4
    assert summary["tracking_error_m"]["supports"]["max"] < 1e-4
    assert summary["mpc_solve_ms"]["median"] > 0
    cpu = summary["cpu_s"]  # per process; together, what this test saw the run's tree use
    assert set(cpu) == {"orchestrator", "ground_station", "work", *summary["multipath_steps"]}
    assert all(seconds > 0 for seconds in cpu.values())
    used = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    assert 0.9 * used < sum(cpu.values()) <= used + 0.01, (cpu, used)
    assert (tmp_path / "a" / "gcs.tlog").stat().st_size > 0
    assert _children_of(scenario) == []
    assert _processes_of(tmp_path / "a") == []
    analyzed = subprocess.run(
        [sys.executable, "-m", "mission", "analyze", str(tmp_path / "a"), "--plots"],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=ROOT,
    )
    assert analyzed.returncode == 0, analyzed.stderr
    metrics = json.loads(analyzed.stdout)  # the metrics alone (notes go to stderr)
    for name, size in [
        ("trajectories", (1500, 1100)),
        ("error", (1300, 420)),  # its legend beside the axes
        ("g_update", (1600, 900)),
    ]:
        header = (tmp_path / "a" / "plots" / f"{name}.png").read_bytes()[:24]
        assert header[:8] == b"\x89PNG\r\n\x1a\n"
        assert struct.unpack(">II", header[16:24]) == size
    assert metrics == {k: summary[k] for k in metrics}, "the tlog alone gives the same metrics"
    assert summary["scenario_source"] == str(scenario)
    _analysis_keeps_a_summary_its_tlog_cannot_hold(tmp_path / "a", tmp_path / "cut")

    # The same seed again, with every link signed, every MPC solved in the ground station (no
    # helper process), and the station and each vehicle started as `python -m ...` instead of
    # forked: identical results.
    key = tmp_path / "link.key"
    key.write_bytes(bytes(range(32)))
    again = _run(
        scenario,
        tmp_path / "b",
        "--seed",
        "2",
        "--signing-key",
        str(key),
        "--no-mpc-helper",
        "--process-start",
        "exec",
    )
    assert again.returncode == 0, again.stderr
    second = json.loads((tmp_path / "b" / "summary.json").read_text())
    assert _steady(summary) == _steady(second)
    # A tick asked again is answered with the step's telemetry signed afresh: a replayed
    # signature would be refused.
    assert second["link"]["rejected"] == {}, second["link"]
    dump = subprocess.run(
        [
            str(Path(sys.executable).parent / "mavlogdump.py"),
            "--types",
            "SET_POSITION_TARGET_LOCAL_NED",
            str(tmp_path / "b" / "gcs.tlog"),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert dump.returncode == 0, dump.stderr
    sent = {  # one per vehicle and cycle (a batch sent again after a late marker is logged again)
        re.search(r"time_boot_ms : (\d+), target_system : (\d+)", line).groups()
        for line in dump.stdout.splitlines()
        if "SET_POSITION_TARGET_LOCAL_NED" in line
    }
    assert len(sent) == 4 * summary["control_cycles"]

    # The fast tlog reader (skips undecoded kinds) equals pymavlink's, plain and signed.
    from mission.analysis.metrics import read_tlog
    from mission.config.scenario import load_scenario
    from tests.tlog_reference import read_tlog_with_mavutil

    loaded = load_scenario(str(scenario))
    for run in ("a", "b"):
        fast = read_tlog(tmp_path / run / "gcs.tlog", loaded)
        reference = read_tlog_with_mavutil(tmp_path / run / "gcs.tlog", loaded)
        assert _same_trace(fast, reference)
        assert len(fast.ticks) == summary["control_cycles"]


def _same_trace(a, b) -> bool:
    def arrays_equal(x: dict, y: dict) -> bool:
        return x.keys() == y.keys() and all(np.array_equal(x[k], y[k]) for k in x)

    return (
        a.ticks == b.ticks
        and a.completion == b.completion
        and a.link_events == b.link_events
        and arrays_equal(a.truth, b.truth)
        and arrays_equal(a.estimates, b.estimates)
        and arrays_equal(a.beliefs, b.beliefs)
        and arrays_equal(a.setpoints, b.setpoints)
        and arrays_equal(a.sent_estimates, b.sent_estimates)
    )


def test_a_dead_work_vehicle_ends_the_run_with_a_clear_error(scenario, tmp_path):
    out = tmp_path / "killed"
    # Paced (the short mission takes ~7 s of wall time): in lockstep it can end within a
    # second, before the vehicle is killed.
    run = subprocess.Popen(
        [sys.executable, "-m", "mission", "run", str(scenario), "--out", str(out)]
        + ["--realtime", "--speedup", "5"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    try:
        _wait_for_cycles(out, 3)
        work = vehicle_pids(run.pid, "work")
        assert len(work) == 1, "the work vehicle is running"
        # forked from the run (by default): its command line is the run's
        command = Path(f"/proc/{work[0]}/cmdline").read_bytes().split(b"\0")
        assert command[1:4] == [b"-m", b"mission", b"run"]
        subprocess.run(["kill", "-9", str(work[0])], check=True)
        _, stderr = run.communicate(timeout=120)
    finally:
        if run.poll() is None:
            run.kill()
    assert run.returncode == 1
    assert "work died" in stderr and "logs kept" in stderr
    assert (out / "gcs.tlog").exists() and (out / "work.log").exists()
    assert _children_of(scenario) == []


def test_a_lossy_slow_link_still_completes_and_counts_its_losses(short_run, tmp_path):
    clean, scenario = short_run  # the same scenario file: the summaries name it
    out = tmp_path / "lossy"
    result = _run(scenario, out, "--link-loss", "0.2", "--link-delay-ms", "5")
    assert result.returncode == 0, result.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["completed"] is True
    link = summary["link"]
    assert (link["loss"], link["delay_ms"]) == (0.2, 5.0)
    # the ground station drops a fifth of what it sends (binomial: +-4 sd over ~450 datagrams:
    # each vehicle's commands and tick leave in one datagram a cycle); lost batches and steps
    # are asked again
    assert link["sent_out"] >= 4 * summary["control_cycles"]
    assert link["dropped_out"] / link["sent_out"] == pytest.approx(0.2, abs=0.075)
    assert link["tick_resends"] > 0
    assert _children_of(scenario) == []
    # Every lost batch or step was asked again in time, so the run is the lossless run exactly.
    lossless = json.loads((clean / "summary.json").read_text())
    assert link["late_steps"] == 0
    # (a batch sent again after the vehicle stepped on the first carries an estimate it has
    # taken: it ignores it, and its belief goes on as in the lossless run)
    refused = [
        re.search(r"'estimate not newer than the last': (\d+)", (out / f"{name}.log").read_text())
        for name in ("work", "support-1", "support-2", "support-3")
    ]
    assert sum(int(found.group(1)) for found in refused if found) > 0
    assert _steady(summary) | {"link": None} == _steady(lossless) | {"link": None}
    assert _records(out) == _records(clean)


def _records(out: Path) -> list[dict]:
    """The ground station's records without their wall-clock figures (and without the MPCs'
    predicted paths, which the lockstep digest predates)."""
    records = [json.loads(line) for line in (out / "records.jsonl").read_text().splitlines()]
    for record in records:
        del record["cycle_ms"]
        for solve in record["mpc"].values():
            del solve["ms"]
            del solve["path"]
    return records


def test_an_observer_sees_every_vehicle_without_disturbing_the_run(scenario, tmp_path):
    import os
    import socket

    os.environ.setdefault("MAVLINK20", "1")
    from pymavlink import mavutil

    probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    probe.bind(("127.0.0.1", 0))
    port = probe.getsockname()[1]
    probe.close()
    observer = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}", dialect="ardupilotmega")
    out = tmp_path / "observed"
    run = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "mission",
            "run",
            str(scenario),
            "--out",
            str(out),
            "--seed",
            "2",
            "--realtime",
            "--speedup",
            "10",
            "--observer",
            f"127.0.0.1:{port}",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    seen: dict[int, set[str]] = {}
    try:
        while run.poll() is None:
            message = observer.recv_match(blocking=True, timeout=0.2)
            if message is not None and message.get_type() != "BAD_DATA":
                seen.setdefault(message.get_srcSystem(), set()).add(message.get_type())
        _, stderr = run.communicate(timeout=60)
    finally:
        if run.poll() is None:
            run.kill()
        observer.close()
    assert run.returncode == 0, stderr
    assert json.loads((out / "summary.json").read_text())["completed"] is True
    assert set(seen) == {1, 2, 3, 4}
    for system in (2, 3, 4):
        assert {"HEARTBEAT", "GPS_RAW_INT", "LANDING_TARGET", "GLOBAL_POSITION_INT"} <= seen[system]
    assert _children_of(scenario) == []


def _start_in_own_group(out: Path, sigint_ignored: bool = False) -> subprocess.Popen:
    """`mission run along` in a process group of its own, as a terminal would start it (or as
    a shell starts a background job: with SIGINT ignored)."""

    def ignore_sigint() -> None:
        signal.signal(signal.SIGINT, signal.SIG_IGN)

    return subprocess.Popen(
        [sys.executable, "-m", "mission", "run", "along", "--out", str(out), "--mpc-helper"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
        start_new_session=True,
        preexec_fn=ignore_sigint if sigint_ignored else None,
    )


def _wait_for_cycles(out: Path, cycles: int, timeout_s: float = 120.0) -> None:
    deadline = time.monotonic() + timeout_s
    records = out / "records.jsonl"
    while not (records.exists() and len(records.read_text().splitlines()) >= cycles):
        assert time.monotonic() < deadline, "the run did not get going"
        time.sleep(0.05)


def _gone(out: Path, timeout_s: float = 15.0) -> bool:
    deadline = time.monotonic() + timeout_s
    while _processes_of(out) and time.monotonic() < deadline:
        time.sleep(0.05)
    return _processes_of(out) == []


@pytest.mark.parametrize("sigint_ignored", [False, True], ids=["terminal", "background-job"])
def test_ctrl_c_stops_every_process_of_a_run_and_keeps_its_logs(tmp_path, sigint_ignored):
    """Ctrl-C reaches the run's whole process group: the ground station, its forked helper
    and the forked vehicles all end, and the run says it was interrupted; also when it was
    started with SIGINT ignored, as a shell starts a background job (an explicit SIGINT then
    still stops it, and the run does not mistake its interrupted ground station for a
    failure)."""
    out = tmp_path / "interrupted"
    run = _start_in_own_group(out, sigint_ignored)
    try:
        _wait_for_cycles(out, 5)
        assert len(_processes_of(out)) == 7  # run, station, helper, four vehicles
        os.killpg(run.pid, signal.SIGINT)
        stdout, stderr = run.communicate(timeout=60)
    finally:
        if run.poll() is None:
            os.killpg(run.pid, signal.SIGKILL)
    assert run.returncode == 130 and "interrupted" in stdout + stderr, stdout + stderr
    assert _gone(out)
    assert (out / "gcs.tlog").stat().st_size > 0 and "steps to t=" in (out / "work.log").read_text()


def test_a_signal_to_the_run_alone_leaves_no_zombie_helper(tmp_path):
    """SIGINT to the run's own process (kill -INT, not the group): it stops the ground
    station with SIGTERM, which ends it as Ctrl-C does, so it waits for its MPC helper (it
    died at once before, and the helper lingered <defunct> until init reaped it)."""
    out = tmp_path / "signalled"
    run = _start_in_own_group(out)
    try:
        _wait_for_cycles(out, 5)
        helpers = [pid for pid in _processes_of(out) if _name_of(pid) == "gcs-mpc-helper"]
        assert len(helpers) == 1
        os.kill(run.pid, signal.SIGINT)
        stdout, stderr = run.communicate(timeout=60)
    finally:
        if run.poll() is None:
            os.killpg(run.pid, signal.SIGKILL)
    assert run.returncode == 130, stdout + stderr
    assert not Path(f"/proc/{helpers[0]}").exists(), "the helper is left, a zombie"


def _name_of(pid: str) -> str:
    try:
        return Path(f"/proc/{pid}/comm").read_text().strip()
    except OSError:
        return ""


def test_a_killed_run_takes_its_processes_with_it(tmp_path):
    """SIGKILL gives the run no chance to stop anything: its children notice their parent's
    death (and the helper its station's) and end by themselves."""
    out = tmp_path / "killed-run"
    run = _start_in_own_group(out)
    try:
        _wait_for_cycles(out, 5)
        run.kill()
        run.wait(timeout=30)
        assert _gone(out)
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(run.pid, signal.SIGKILL)
