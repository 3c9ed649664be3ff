"""A run whose multipath comes from geometry, real processes end to end: the
supports' receivers report float fixes where they track a reflection, and the summary's true
errors equal the tlog's fixes against its truth (read by pymavlink)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from pymavlink import mavutil

from mission.config.scenario import load_scenario
from mission.world.frames import GeodeticFrame
from tests.processes import EXIT_NOT_COMPLETED, mission

pytestmark = pytest.mark.slow  # starts a run

SHORT_RIVER = """
extends: river
name: short-river
run: {timeout_s: 20.0}
integrity: {enabled: true}
"""


def test_a_geometry_run_reports_float_fixes_and_their_true_errors(tmp_path):
    scenario = tmp_path / "short-river.yaml"
    scenario.write_text(SHORT_RIVER)
    result = mission("run", str(scenario), "--out", str(tmp_path / "run"))
    assert result.returncode == EXIT_NOT_COMPLETED, result.stderr
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["gnss_multipath"] == "geometry"
    frame = GeodeticFrame(load_scenario(str(scenario)).world.anchor)
    log = mavutil.mavlink_connection(str(tmp_path / "run" / "gcs.tlog"), dialect="ardupilotmega")
    fix_types, truth, errors = set(), {}, []
    while (message := log.recv_match(type=["GPS_RAW_INT", "SIM_STATE"])) is not None:
        source = message.get_srcSystem()
        if source in (1, 255):
            continue
        if message.get_type() == "SIM_STATE":
            truth[source] = frame.from_degE7(message.lat_int, message.lon_int, message.alt)
        elif message.fix_type >= 3 and source in truth:
            fix_types.add(message.fix_type)
            fix = frame.from_degE7(message.lat, message.lon, message.alt / 1000)
            errors.append(float(np.linalg.norm(fix - truth[source])))
    assert 5 in fix_types  # RTK float: a reflection tracked beside the deck
    pooled = summary["supports_gnss_error_m"]
    assert pooled["max"] == pytest.approx(max(errors), abs=0.05)
    assert pooled["max"] > 0.5 and summary["gnss_error_steps_total"] > 0
