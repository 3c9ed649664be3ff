"""The Python API against the command line and against the run's files read independently:
``mission.run`` gives what ``mission run`` gives (records and summary, timings aside),
``load_run``'s frames are the tlog's and the records' own numbers, overrides are validated
as YAML is before anything starts."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from pymavlink import mavutil

import mission
from mission.config.errors import InputError, ScenarioError
from mission.studies.verify import is_timing
from mission.world.frames import GeodeticFrame
from tests.processes import ROOT

# what two lockstep runs of one mission may differ in: the machine's figures
MACHINE = {"wall_time_s", "realtime_factor", "cpu_s", "compile_s", "compiled", "link", "provenance"}
MACHINE |= {"mpc_solve_ms", "scenario_source"}


def _decided(summary: dict) -> dict:
    return {k: v for k, v in summary.items() if k not in MACHINE and not is_timing(k)}


def _records(run_dir) -> list[dict]:
    """records.jsonl without its timings (each cycle's and each solve's milliseconds)."""
    records = []
    for line in (run_dir / "records.jsonl").read_text().splitlines():
        record = json.loads(line)
        record.pop("cycle_ms", None)
        for plan in (record.get("mpc") or {}).values():
            plan.pop("ms", None)
        records.append(record)
    return records


@pytest.mark.slow
def test_run_from_python_gives_what_the_command_line_gives(short_run, tmp_path):
    run_dir, scenario = short_run
    out = tmp_path / "api"
    script = (
        "from mission import run; "
        f"r = run({str(scenario)!r}, seed=0, out={str(out)!r}); "
        "print(r.summary.completion_time_s)"
    )
    result = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT, timeout=600
    )
    assert result.returncode == 0, result.stderr
    cli = json.loads((run_dir / "summary.json").read_text())
    api = json.loads((out / "summary.json").read_text())
    assert result.stdout.strip() == str(cli["completion_time_s"])
    assert api["decisions_digest"] == cli["decisions_digest"]
    assert _decided(api) == _decided(cli)
    assert _records(out) == _records(run_dir)


@pytest.mark.slow
def test_the_frames_are_the_runs_own_numbers(short_run):
    run_dir, _ = short_run
    run = mission.load_run(run_dir)
    assert (
        run.summary.decisions_digest
        == json.loads((run_dir / "summary.json").read_text())["decisions_digest"]
    )
    assert run.summary.completed and run.summary.work_error_m.mean > 0
    frame = GeodeticFrame(run.scenario.world.anchor)
    log = mavutil.mavlink_connection(str(run_dir / "gcs.tlog"), dialect="ardupilotmega")
    sim_states = []
    while (message := log.recv_match(type="SIM_STATE")) is not None:
        if message.get_srcSystem() == 2:  # support-1
            sim_states.append(frame.from_degE7(message.lat_int, message.lon_int, message.alt))
    truth = run.truth()
    mine = truth[truth["vehicle"] == "support-1"][["e", "n", "u"]].to_numpy()
    states = np.array(sim_states)
    moved = np.r_[True, np.any(states[1:] != states[:-1], axis=1)]  # the first is sent twice
    assert len(mine) == moved.sum() and np.abs(mine - states[moved]).max() < 1e-9
    records = [json.loads(line) for line in (run_dir / "records.jsonl").read_text().splitlines()]
    estimates = run.estimates()
    work = estimates[estimates["vehicle"] == "work"]
    assert np.allclose(work[["e", "n", "u"]].to_numpy(), [r["xhat"] for r in records])
    beta = estimates[estimates["vehicle"] == "support-2"]["beta"].to_numpy()
    expected = [
        np.nan if r["beta"]["support-2"] is None else r["beta"]["support-2"] for r in records
    ]
    assert np.allclose(beta, expected, equal_nan=True)
    assert set(run.commands()["vehicle"]) == {"work", "support-1", "support-2", "support-3"}
    fixes = run.fixes()
    assert (fixes["error_m"].dropna() < 1.5).all() and len(fixes) > 100
    assert run.g("initial").shape == run.g().shape == (50, 40, 20)
    with pytest.raises(KeyError, match="kept: initial"):
        run.g(7)


@pytest.mark.slow
def test_figures_and_view_are_the_command_lines(short_run, tmp_path):
    run_dir, _ = short_run
    run = mission.load_run(run_dir)
    written = run.figures(tmp_path / "plots")
    assert sorted(p.name for p in written) == ["error.png", "g_update.png", "trajectories.png"]
    assert all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in written)
    assert run.view(save=tmp_path / "run.rrd") == 0 and (tmp_path / "run.rrd").stat().st_size > 0


@pytest.mark.slow
def test_overrides_fly_and_read_back(tmp_path):
    run = mission.run(
        "along",
        seed=1,
        overrides={"run.timeout_s": 15.0, "fusion.rho_threshold": 0.5},
        out=tmp_path / "short",
        g_snapshots="ends",
    )
    assert not run.summary.completed and run.summary.control_cycles == 30
    again = mission.load_run(tmp_path / "short")
    assert again.scenario.fusion.rho_threshold == 0.5 and again.scenario.run.timeout_s == 15.0
    assert again.g_snapshots() == ["initial", "final"]
    assert again.records().shape[0] == 30


@pytest.mark.parametrize(
    ("kwargs", "error", "named"),
    [
        ({"overrides": {"map.eta": 5.0}}, ScenarioError, "map.eta"),
        ({"overrides": {"fusion.no_such": 1}}, ScenarioError, "fusion.no_such"),
        ({"seed": -1}, InputError, "run(): seed"),
        ({"method": "fast"}, InputError, "run(): method"),
        ({"speedup": 1e6}, InputError, "run(): speedup"),
        ({"observer": "nowhere"}, InputError, "run(): observer"),
        ({"stall_s": -1.0}, InputError, "stall_s"),
    ],
)
def test_bad_arguments_raise_before_anything_starts(tmp_path, kwargs, error, named):
    with pytest.raises(error) as raised:
        mission.run("along", out=tmp_path / "never", **kwargs)
    assert named in str(raised.value) and "\n" not in str(raised.value)
    assert not (tmp_path / "never").exists()


def test_a_folder_holding_a_run_is_refused_without_force(tmp_path):
    (tmp_path / "summary.json").write_text("{}")
    with pytest.raises(InputError, match=r"run\(\): out: .* holds a run .* force"):
        mission.run("along", out=tmp_path)
