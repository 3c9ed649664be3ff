"""Safety end to end: the paper's form one setting away (records as they were), a crash that
ends a run (reported by the vehicle, recorded in the summary), the summary's safety figures
against an independent reading of the tlog (pymavlink, trimesh), and a blind work UAV that
holds."""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import numpy as np
import pytest
import trimesh

from mission.analysis.decisions import decisions_digest
from mission.analysis.records_file import read_records
from mission.config.scenario import load_scenario
from mission.world.model import World
from tests.margins_check import independent_truth, run_margins
from tests.processes import EXIT_NOT_COMPLETED, mission

pytestmark = pytest.mark.slow  # every test here starts processes

PAPER_FORM = """
extends: along
name: paper-form
control: {{min_separation_m: 0, clearance_m: 0}}
run: {{stop_on_crash: {stop}}}
"""
# Along AC seed 0 in the paper's form: its cycles and the digest of its decisions
# (mission.analysis.decisions: every record but its wall-clock fields, numbers to 1e-6), the
# same whatever SIMD numpy and OpenBLAS use. A change that means to alter the paper's form
# says so by updating it. The digest holds every decision of the run at once; a second test
# states the run's outcome in its own terms, which say what moved when the digest does.
PAPER_FORM_DECISIONS = (509, "d20f4eb6c1d54842")


def _paper_form(tmp_path: Path, stop: bool) -> Path:
    path = tmp_path / f"paper-form-{stop}.yaml"
    path.write_text(PAPER_FORM.format(stop=str(stop).lower()))
    return path


@pytest.fixture(scope="module")
def paper_form_run(tmp_path_factory) -> Path:
    """Along AC seed 0 in the paper's form, flown through its contacts: its folder."""
    tmp = tmp_path_factory.mktemp("paper-form")
    result = mission("run", str(_paper_form(tmp, False)), "--out", str(tmp / "run"))
    assert result.returncode == 0, result.stderr
    return tmp / "run"


@pytest.mark.determinism
def test_the_papers_form_is_one_setting_away(paper_form_run):
    records = read_records(paper_form_run / "records.jsonl")
    assert (len(records), decisions_digest(records)) == PAPER_FORM_DECISIONS
    summary = json.loads((paper_form_run / "summary.json").read_text())
    assert summary["decisions_digest"] == PAPER_FORM_DECISIONS[1]
    safety = summary["safety"]
    # without margins support-1 flies into the deck's edge and on: recorded, not stopped
    assert safety["contacts"] and not any(c["crash"] for c in safety["contacts"])
    assert "support-1" in safety["touching_vehicles"]
    assert {c["vehicle"] for c in safety["contacts"]} >= {"support-1"}


@pytest.mark.determinism
def test_what_the_papers_form_digest_pins(paper_form_run):
    """The run the digest holds, in the terms a reader of it sees: where a change moves the
    digest, this says what moved (or that only a decision beyond these did)."""
    summary = json.loads((paper_form_run / "summary.json").read_text())
    assert (summary["completion_time_s"], summary["multipath_steps"]) == (
        254.5,
        {"support-1": 13, "support-2": 1, "support-3": 0},
    )
    assert summary["work_error_m"] == {"mean": 0.1408, "p95": 0.2686, "max": 0.6355}
    first = summary["safety"]["contacts"][0]
    assert (first["vehicle"], first["with"], first["t"]) == ("support-1", "structure", 22.5)


@pytest.fixture(scope="module")
def crashed(tmp_path_factory) -> tuple[Path, Path]:
    """(the run's folder, its scenario file): Along AC seed 0 without margins, stopped at
    the first crash."""
    tmp = tmp_path_factory.mktemp("crash")
    out, scenario = tmp / "run", _paper_form(tmp, True)
    result = mission("run", str(scenario), "--out", str(out))
    assert result.returncode == EXIT_NOT_COMPLETED, result.stderr  # flown, not completed
    assert "STOPPED: support-1 crashed" in result.stdout
    return out, scenario


def test_a_crash_stops_the_run_as_failed_with_the_reason(crashed):
    crashed, _ = crashed
    summary = json.loads((crashed / "summary.json").read_text())
    assert not summary["completed"] and summary["completion_time_s"] is None
    (contact,) = summary["safety"]["contacts"]
    assert contact["crash"] and (contact["vehicle"], contact["with"]) == ("support-1", "structure")
    assert summary["stopped"] == f"support-1 crashed at {contact['t']:.1f} s"
    ground_station_log = (crashed / "ground_station.log").read_text()
    assert "Run stopped: support-1 crashed" in ground_station_log


def test_the_safety_figures_match_an_independent_reading(crashed):
    crashed, scenario_file = crashed
    scenario = load_scenario(str(scenario_file))
    safety = json.loads((crashed / "summary.json").read_text())["safety"]
    tracks = independent_truth(crashed / "gcs.tlog", scenario)
    name = {1: "work", 2: "support-1", 3: "support-2", 4: "support-3"}
    # closest approach at the common samples: never below the summary's (which also looks
    # between samples), and within how far two vehicles can close in half a step
    for a, b in itertools.combinations(sorted(tracks), 2):
        times = np.intersect1d(tracks[a][0], tracks[b][0])
        pa = tracks[a][1][np.searchsorted(tracks[a][0], times)]
        pb = tracks[b][1][np.searchsorted(tracks[b][0], times)]
        sampled = float(np.linalg.norm(pa - pb, axis=1).min())
        reported = safety["closest_approach_m"][f"{name[a]}/{name[b]}"]
        assert reported - 1e-3 <= sampled <= reported + 1.0
    mesh = World(scenario).structure.mesh
    query = trimesh.proximity.ProximityQuery(mesh)
    for system, (_, positions) in tracks.items():
        sampled = float(min(np.abs(query.signed_distance(positions)).min(), positions[:, 2].min()))
        reported = safety["least_clearance_m"][name[system]]
        assert reported - 1e-3 <= sampled <= reported + 0.5
    crash = safety["contacts"][0]
    assert safety["worst_clearance"]["who"] == "support-1"
    assert safety["worst_clearance"]["distance_m"] < scenario.vehicle.radius_m
    assert abs(safety["worst_clearance"]["t"] - crash["t"]) < 0.5


BLIND = """
extends: along
name: blind
camera: {range_m: 1.0}
run: {timeout_s: 10.0}
"""


def test_a_blind_work_uav_holds_where_it_is(tmp_path):
    """No support can see the work UAV (camera range 1 m): every cycle is blind, the ground
    station streams it no estimate, and its truth does not move."""
    path = tmp_path / "blind.yaml"
    path.write_text(BLIND)
    result = mission("run", str(path), "--out", str(tmp_path / "run"))
    assert result.returncode == EXIT_NOT_COMPLETED, result.stderr
    records = [
        json.loads(line) for line in (tmp_path / "run/records.jsonl").read_text().splitlines()
    ]
    assert len(records) >= 15 and all(r["blind"] for r in records)
    scenario = load_scenario(str(path))
    times, positions = independent_truth(tmp_path / "run" / "gcs.tlog", scenario)[1]
    assert len(times) >= 15
    drift = np.linalg.norm(positions - positions[0], axis=1).max()
    assert drift < 1e-3  # tracking noise is 0: not a millimetre
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["diagnostics"]["blind_cycles"] == len(records)


def test_the_defaults_keep_their_margins_along_the_whole_run(along_run):
    """Along AC seed 0 with the defaults: no contact, and the truth (read by pymavlink) keeps
    every pair 2 m apart and every UAV 0.5 m from the structure (trimesh) and the ground, at
    every sample."""
    summary = json.loads((along_run / "summary.json").read_text())
    assert summary["completed"] and summary["safety"]["contacts"] == []
    kept = run_margins(along_run, "along")
    assert (kept.separation_m, kept.clearance_m) == (2.0, 0.5)
    assert kept.kept, kept
