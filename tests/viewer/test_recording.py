"""The 3-D view's recording, read back with Rerun's own API and checked against the run's files
read independently (pymavlink's tlog reader, records.jsonl, the G snapshots); and the live view
(``mission run --view``) recording the same rows as the replay (``mission view``)."""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import numpy as np
import pymap3d
import pytest

from mission.analysis.metrics import read_tlog, work_errors
from mission.config.scenario import load_scenario
from mission.viewer import frame as f
from tests.viewer.conftest import mission
from tests.viewer.rrd import points, read_rrd, times

pytestmark = pytest.mark.slow  # runs missions
SUPPORTS = ("support-1", "support-2", "support-3")


def _records(run: Path) -> list[dict]:
    return [json.loads(line) for line in (run / "records.jsonl").read_text().splitlines()]


def _tlog_messages(run: Path, kind: str) -> list:
    from pymavlink import mavutil

    log = mavutil.mavlink_connection(str(run / "gcs.tlog"), dialect="ardupilotmega")
    return list(iter(lambda: log.recv_match(type=kind), None))


def test_every_entity_is_recorded(replayed):
    _, _, rows = replayed
    expected = {"/world/structure", "/world/zones", "/world/workspace", "/map/G"}
    expected |= {"/plots/work_error", "/estimate/work", "/uav/work", "/plan/work/current"}
    for name in SUPPORTS:
        expected |= {f"/{kind}/{name}" for kind in ("uav", "estimate", "gnss", "sight", "mpc")}
        expected |= {f"/plots/{kind}/{name}" for kind in ("beta", "solve_ms", "zone_steps")}
        expected |= {f"/plots/fused/{name}", f"/plan/{name}", f"/plan/{name}/current"}
    assert expected <= set(rows)


def test_true_paths_and_estimates_equal_the_run_to_a_millimetre(replayed):
    run, scenario_file, rows = replayed
    trace = read_tlog(run / "gcs.tlog", load_scenario(str(scenario_file)))
    for system, name in enumerate(("work", *SUPPORTS), start=1):
        track_times, track = trace.track(system)
        entity = rows[f"/uav/{name}"]
        assert np.array_equal(times(entity), track_times)
        assert np.abs(points(entity) - track).max() < 1e-3
    records = _records(run)
    estimate = rows["/estimate/work"]
    assert np.array_equal(times(estimate), [r["t"] for r in records])
    assert np.abs(points(estimate) - [r["xhat"] for r in records]).max() < 1e-3
    for name in SUPPORTS:
        yhat = points(rows[f"/estimate/{name}"])
        assert np.abs(yhat - [r["yhat"][name] for r in records]).max() < 1e-3
        fused = rows[f"/plots/fused/{name}"]["Scalars:scalars"]
        assert [v[0] for v in fused] == [float(name in r["consistent"]) for r in records]


def test_mpc_paths_beta_and_solve_times_are_the_records(replayed):
    run, _, rows = replayed
    records = _records(run)
    for name in SUPPORTS:
        strips = rows[f"/mpc/{name}"]["LineStrips3D:strips"]
        assert len(strips) == len(records)
        recorded = np.array([row[0] for row in strips], dtype=float)
        assert np.abs(recorded - [r["mpc"][name]["path"] for r in records]).max() < 1e-3
        solve = [v[0] for v in rows[f"/plots/solve_ms/{name}"]["Scalars:scalars"]]
        assert np.allclose(solve, [r["mpc"][name]["ms"] for r in records])
        betas = [r["beta"][name] for r in records if r["beta"].get(name) is not None]
        assert np.allclose([v[0] for v in rows[f"/plots/beta/{name}"]["Scalars:scalars"]], betas)
    changes = 1 + sum(a["k"] != b["k"] for a, b in itertools.pairwise(records))
    assert len(rows["/plan/work/current"]["sim_time"]) == changes


def test_gnss_fixes_and_sight_lines_are_every_message_of_the_tlog(replayed):
    run, scenario_file, rows = replayed
    anchor = load_scenario(str(scenario_file)).world.anchor
    fixes = [m for m in _tlog_messages(run, "GPS_RAW_INT") if m.fix_type >= 3]
    sights = _tlog_messages(run, "LANDING_TARGET")
    for number, name in enumerate(SUPPORTS, start=2):
        mine = [m for m in fixes if m.get_srcSystem() == number]
        enu = [
            pymap3d.geodetic2enu(
                m.lat / 1e7, m.lon / 1e7, m.alt / 1e3, anchor.lat_deg, anchor.lon_deg, anchor.alt_m
            )
            for m in mine
        ]
        assert np.abs(points(rows[f"/gnss/{name}"]) - np.array(enu)).max() < 1e-3
        seen = [bool(m.position_valid) for m in sights if m.get_srcSystem() == number]
        colours = [tuple(_rgb(c[0])) for c in rows[f"/sight/{name}"]["LineStrips3D:colors"]]
        assert colours == [f.VISIBLE_COLOUR if s else f.BLOCKED_COLOUR for s in seen]


def test_errors_steps_in_a_zone_and_g_follow_the_metrics_and_snapshots(replayed):
    run, scenario_file, rows = replayed
    trace = read_tlog(run / "gcs.tlog", load_scenario(str(scenario_file)))
    error_times, errors = work_errors(trace)
    recorded = rows["/plots/work_error"]
    assert np.array_equal(times(recorded), error_times)
    assert np.abs(np.array([v[0] for v in recorded["Scalars:scalars"]]) - errors).max() < 1e-3
    summary = json.loads((run / "summary.json").read_text())
    for name in SUPPORTS:
        counts = rows[f"/plots/zone_steps/{name}"]["Scalars:scalars"]
        assert counts[-1][0] == summary["multipath_steps"][name]
    snapshots = sorted((run / "g").glob("G_*.npy"))
    voxels = rows["/map/G"]
    assert len(voxels["sim_time"]) == len(snapshots)
    initial, final = np.load(run / "g" / "G_initial.npy"), np.load(run / "g" / "G_final.npy")
    changed = np.argwhere(np.abs(final - initial) > f.G_CHANGED_M)
    assert np.array_equal(np.array(voxels["VoxelGridMap:voxel_indices"][-1]), changed)
    assert np.allclose(voxels["VoxelGridMap:values"][-1], final[tuple(changed.T)], atol=1e-6)


LIVE = """
import sys
from pathlib import Path
from mission.procs.numerics import prepare_numerics
prepare_numerics()  # as `mission run --view` computes (this test's own process is not pinned)
from mission.config.scenario import load_scenario
from mission.runs.orchestrator import RunOptions, run_mission
from mission.viewer.live import LiveView
scenario_file, out, save = sys.argv[1:4]
scenario = load_scenario(scenario_file)
live = LiveView(Path(out), scenario, None, save=Path(save))
run_mission(RunOptions(scenario_file, "ac", 0, Path(out)), scenario, live)
"""


def test_the_live_view_records_what_the_replay_does(replayed, tmp_path):
    """A live run (streamed as it flies) and the replay of it hold the same rows."""
    import subprocess
    import sys

    _, scenario_file, _ = replayed
    out = tmp_path / "live-run"
    live = [sys.executable, "-c", LIVE, str(scenario_file), str(out), str(tmp_path / "live.rrd")]
    subprocess.run(live, check=True, capture_output=True, timeout=600)
    assert mission("view", str(out), "--save", str(tmp_path / "replay.rrd")).returncode == 0
    streamed, replay = read_rrd(tmp_path / "live.rrd"), read_rrd(tmp_path / "replay.rrd")
    assert set(streamed) == set(replay)
    for entity, columns in replay.items():
        if entity != "/__properties":
            assert streamed[entity] == columns, entity


def _rgb(packed: int) -> tuple[int, int, int]:
    """Rerun's packed 0xRRGGBBAA colour as (r, g, b)."""
    return (packed >> 24) & 255, (packed >> 16) & 255, (packed >> 8) & 255
