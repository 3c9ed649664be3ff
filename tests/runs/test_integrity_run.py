"""The integrity monitor in a real run: a support whose receiver glitches 2.2 m is excluded
within a cycle of the glitch, said so in a STATUSTEXT (chunked where long) in the tlog, and
restored once the glitch is over; the summary counts it from the truth; the 3-D view marks
the excluded support and draws each estimate's protection radius."""

from __future__ import annotations

import json

import numpy as np
import pytest
from pymavlink import mavutil

from mission.link.statustext import StatusChunks
from tests.processes import EXIT_NOT_COMPLETED, mission
from tests.viewer.rrd import read_rrd

pytestmark = pytest.mark.slow  # starts a run

GLITCHED = """
extends: along
name: glitched
run: {timeout_s: 20.0}
faults: [{at_s: 5, vehicle: support-3, param: SIM_GPS1_GLTCH_X, value: 0.00002, duration_s: 5}]
integrity: {enabled: true}
"""


def _station_texts(tlog) -> list[tuple[float, str]]:
    log = mavutil.mavlink_connection(str(tlog), dialect="ardupilotmega")
    chunks, said = StatusChunks(), []
    while (message := log.recv_match(type="STATUSTEXT")) is not None:
        if message.get_srcSystem() == 255:
            text = chunks.add(message)
            if text is not None:
                said.append((message._timestamp, text))
    return said


@pytest.fixture(scope="module")
def glitched(tmp_path_factory):
    """The glitched run's folder."""
    tmp_path = tmp_path_factory.mktemp("glitched")
    scenario = tmp_path / "glitched.yaml"
    scenario.write_text(GLITCHED)
    result = mission("run", str(scenario), "--out", str(tmp_path / "run"))
    assert result.returncode == EXIT_NOT_COMPLETED, result.stderr
    return tmp_path


def test_a_glitched_support_is_excluded_at_once_and_restored_after(glitched):
    tmp_path = glitched
    texts = [text for _, text in _station_texts(tmp_path / "run" / "gcs.tlog")]
    excluded = [t for t in texts if t.startswith("Integrity: support-3 excluded (")]
    assert excluded and "test, 2." in excluded[0]  # the 2.2 m glitch, seen as such
    assert texts.index(excluded[0]) < texts.index("Integrity: support-3 restored")
    records = [json.loads(line) for line in (tmp_path / "run" / "records.jsonl").open()]
    out = [r["t"] for r in records if "support-3" in r["integrity"]["excluded"]]
    assert 5.0 <= out[0] <= 5.5 and 10.0 <= out[-1] <= 14.0  # at once; back after the glitch
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    integrity = summary["integrity"]
    assert integrity["lying_faults"] == 1 and integrity["missed_detections"] == 0
    assert integrity["detected_faults"] == 1 and integrity["time_to_detect_s"] <= 0.5
    assert integrity["false_alarms"] == 0
    assert summary["safety"]["contacts"] == []


def test_the_view_marks_the_excluded_support_and_draws_every_protection_radius(glitched):
    run = glitched / "run"
    recording = glitched / "run.rrd"
    assert mission("view", str(run), "--save", str(recording)).returncode == 0
    rows = read_rrd(recording)
    records = [json.loads(line) for line in (run / "records.jsonl").open()]
    badge = rows["/integrity/support-3/excluded"]["Points3D:radii"]
    shown = [row[0] > 0 for row in badge]
    assert shown == ["support-3" in r["integrity"]["excluded"] for r in records]
    assert any(shown)
    spheres = rows["/integrity/work/protection"]["Ellipsoids3D:half_sizes"]
    radii = [r["integrity"]["protection_m"]["work"] for r in records]
    assert np.allclose([row[0][0] for row in spheres], [x for x in radii if x is not None])
