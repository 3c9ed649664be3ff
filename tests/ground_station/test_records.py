"""What a ground station writes of G: every snapshot, the ends only, or none; the command lines
offer the same choices the records know."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from ground_station.records import SNAPSHOT_EVERY, RunRecords
from mission.config.run_outputs import G_SNAPSHOTS


@pytest.mark.parametrize(
    ("mode", "written"),
    [
        ("every", {"G_initial.npy", f"G_{SNAPSHOT_EVERY:05d}.npy", "G_final.npy"}),
        ("ends", {"G_initial.npy", "G_final.npy"}),
        ("none", None),
    ],
)
def test_a_run_keeps_the_snapshots_it_is_asked_for(tmp_path, mode, written):
    records = RunRecords(tmp_path, mode)
    g = SimpleNamespace(values=np.arange(6.0))
    for label in ("initial", f"{SNAPSHOT_EVERY:05d}", "final"):
        records.snapshot(g, label)
    records.close()
    g_dir = tmp_path / "g"
    if written is None:
        assert not g_dir.exists()
    else:
        assert {p.name for p in g_dir.iterdir()} == written
        assert np.array_equal(np.load(g_dir / "G_final.npy"), np.arange(6.0))


def test_an_unknown_mode_is_refused():
    with pytest.raises(ValueError, match="g_snapshots"):
        RunRecords(None, "some")  # refused before anything is opened


def test_the_command_lines_offer_the_records_choices():
    from ground_station.cli import build_parser
    from mission.cli import build_parser as mission_parser

    assert G_SNAPSHOTS == ("every", "ends", "none")
    assert build_parser().parse_args(["--g-snapshots", "ends"]).g_snapshots == "ends"
    run = mission_parser().parse_args(["run", "along", "--g-snapshots", "none"])
    assert run.g_snapshots == "none"
    with pytest.raises(SystemExit):
        mission_parser().parse_args(["run", "along", "--g-snapshots", "some"])
