"""The ground station against real vehicle processes: a short mission end to end."""

from __future__ import annotations

import contextlib
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from pymavlink import mavutil

import mission.cli as mission_cli
from mission.config.scenario import load_scenario
from mission.link.plan_files import write_plan
from mission.planning.planner import plan_supports
from mission.world.model import World
from tests.processes import ROOT, vehicle_process

SHORT = """
extends: along
name: short-along
task:
  work_waypoints_m: [[-6.0, -3.0, 7.0], [-3.0, -3.0, 7.0], [0.0, -3.0, 7.0]]
  waypoints_dir: plan
run: {{timeout_s: 120.0}}
world:
  zones:
    - {{name: test, min_m: {lo}, max_m: {hi}, offset_m: [1.0, 0.0, 0.0]}}
"""


@pytest.fixture(scope="module")
def short_scenario(tmp_path_factory) -> Path:
    directory = tmp_path_factory.mktemp("short")
    path = directory / "short.yaml"
    path.write_text(SHORT.format(lo=[24.0, 19.0, 0.0], hi=[25.0, 20.0, 1.0]))
    world = World(load_scenario(str(path)))
    plan = plan_supports(world)
    write_plan(plan, world.scenario, directory / "plan")
    # Put the zone around support 1's first waypoints so the map has something to learn.
    start = plan.supports[0][0]
    lo, hi = (start - [0.5, 2.5, 1.0]).tolist(), (start + [0.5, 2.5, 1.0]).tolist()
    path.write_text(SHORT.format(lo=lo, hi=hi))
    return path


@contextlib.contextmanager
def fleet(scenario: Path, *pacing: str):
    """Three supports, then the work UAV (sending them its truth); lockstep by default."""
    with (
        vehicle_process("support-1", *pacing, scenario=str(scenario), home=None) as s1,
        vehicle_process("support-2", *pacing, scenario=str(scenario), home=None) as s2,
        vehicle_process("support-3", *pacing, scenario=str(scenario), home=None) as s3,
    ):
        truth = [a for s in (s1, s2, s3) for a in ("--truth-out", f"127.0.0.1:{s.truth_port}")]
        with vehicle_process("work", *truth, *pacing, scenario=str(scenario), home=None) as work:
            yield {"work": work, "support-1": s1, "support-2": s2, "support-3": s3}


def _run_station(scenario: Path, out: Path, method: str, vehicles, *extra: str) -> dict:
    addresses = ",".join(f"{n}=127.0.0.1:{v.port}" for n, v in vehicles.items())
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "ground_station",
            "--scenario",
            str(scenario),
            "--method",
            method,
            "--vehicles",
            addresses,
            "--out",
            str(out),
            "--seed",
            "1",
            *extra,
        ],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=ROOT,
    )
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout.strip().splitlines()[-1])


@pytest.mark.slow
def test_a_short_mission_completes_and_is_logged(short_scenario, tmp_path):
    with fleet(short_scenario) as vehicles:
        summary = _run_station(short_scenario, tmp_path, "ac", vehicles)
    assert summary["completed"] is True
    assert 20 < summary["completion_time_s"] < 120
    written = json.loads((tmp_path / "summary.json").read_text())  # a by-hand run has one too
    assert written == summary and written["scenario_source"] == str(short_scenario)
    assert "multipath_steps" not in written  # truth: the ground station does not know it
    assert mission_cli.entry_point(["analyze", str(tmp_path)]) == 0  # no --scenario needed
    analysed = json.loads((tmp_path / "summary.json").read_text())
    assert analysed["control_cycles"] == summary["control_cycles"]
    assert set(analysed["multipath_steps"]) == {"support-1", "support-2", "support-3"}
    records = [json.loads(line) for line in (tmp_path / "records.jsonl").read_text().splitlines()]
    assert len(records) == summary["control_cycles"]
    assert records[-1]["k"] == 2 and records[-1]["arrived"] == 2
    assert sum(r["g_updated_voxels"] > 0 for r in records) > 0
    initial = np.load(tmp_path / "g" / "G_initial.npy")
    final = np.load(tmp_path / "g" / "G_final.npy")
    assert np.any(final != initial), "AC learns the map"
    counts: dict[str, int] = {}
    setpoints = set()  # a batch sent again after a late step marker is logged again
    log = mavutil.mavlink_connection(str(tmp_path / "gcs.tlog"), dialect="ardupilotmega")
    while (message := log.recv_match()) is not None:
        counts[message.get_type()] = counts.get(message.get_type(), 0) + 1
        if message.get_type() == "SET_POSITION_TARGET_LOCAL_NED":
            setpoints.add((message.target_system, message.time_boot_ms))
    for kind in (
        "SIM_STATE",
        "GPS_RAW_INT",
        "LANDING_TARGET",
        "SET_POSITION_TARGET_LOCAL_NED",
        "VISION_POSITION_ESTIMATE",
        "MISSION_ITEM_INT",
        "SYSTEM_TIME",
    ):
        assert counts.get(kind, 0) > 0, kind
    # one per vehicle and cycle, at the cycle's time (a setpoint at any other time is named)
    cycle_ms = {round(r["t"] * 1000) for r in records}
    for system in {target for target, _ in setpoints}:
        sent = {ms for target, ms in setpoints if target == system}
        assert sent == cycle_ms, (system, sorted(sent - cycle_ms), sorted(cycle_ms - sent))
    assert len(setpoints) == 4 * summary["control_cycles"]
    # a record per cycle at the cycle's time, though the next tick goes out before it is written
    t_cont = load_scenario(str(short_scenario)).control.t_cont_s
    assert [r["t"] for r in records] == [
        round(t_cont * (i + 1), 3) for i in range(summary["control_cycles"])
    ]
    assert records[-1]["t"] == summary["completion_time_s"]
    # one tick a vehicle a cycle (and the resends): none after the mission completed
    log = mavutil.mavlink_connection(str(tmp_path / "gcs.tlog"), dialect="ardupilotmega")
    ticks = 0
    while (message := log.recv_match(type="SYSTEM_TIME")) is not None:
        ticks += message.get_srcSystem() == 255
    resends = json.loads((tmp_path / "link.json").read_text())["tick_resends"]
    assert ticks == 4 * summary["control_cycles"] + resends
    # The work vehicle's setpoint and tick leave before the support MPCs are solved (it steps
    # meanwhile): the packet after its setpoint is its tick, not a support's setpoint.
    log = mavutil.mavlink_connection(str(tmp_path / "gcs.tlog"), dialect="ardupilotmega")
    sent = []
    kinds = ["SET_POSITION_TARGET_LOCAL_NED", "SYSTEM_TIME"]
    while (message := log.recv_match(type=kinds)) is not None:
        if message.get_srcSystem() == 255:
            sent.append("tick" if message.get_type() == "SYSTEM_TIME" else message.target_system)
    after_work = [sent[i + 1] for i, item in enumerate(sent[:-1]) if item == 1]
    assert len(after_work) == summary["control_cycles"]
    assert after_work == ["tick"] * (len(after_work) - 1) + [2]  # the last cycle: no tick


@pytest.mark.slow
def test_mavlogdump_reads_the_tlog_and_nac_leaves_g(short_scenario, tmp_path):
    with fleet(short_scenario) as vehicles:
        summary = _run_station(short_scenario, tmp_path, "nac", vehicles)
    assert summary["control_cycles"] > 0
    initial = np.load(tmp_path / "g" / "G_initial.npy")
    np.testing.assert_array_equal(np.load(tmp_path / "g" / "G_final.npy"), initial)
    dump = Path(sys.executable).parent / "mavlogdump.py"
    result = subprocess.run(
        [sys.executable, str(dump), "--types", "SIM_STATE", str(tmp_path / "gcs.tlog")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.count("SIM_STATE") >= summary["control_cycles"] * 4


@pytest.mark.slow
def test_real_time_mode_completes_too(short_scenario, tmp_path):
    with fleet(short_scenario, "--speedup", "10") as vehicles:
        summary = _run_station(
            short_scenario,
            tmp_path,
            "ac",
            vehicles,
            "--speedup",
            "10",
            "--tlog",
            str(tmp_path / "custom.tlog"),
        )
    assert summary["completed"] is True
    assert (tmp_path / "custom.tlog").stat().st_size > 0
    assert not (tmp_path / "gcs.tlog").exists()
