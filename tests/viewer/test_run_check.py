"""``mission view`` refuses a finished run's file that is not what it claims, and warns of one
cut short: each case on files built here (a tlog of real MAVLink 2 records)."""

from __future__ import annotations

import os
import struct
from pathlib import Path

import numpy as np
import pytest

os.environ.setdefault("MAVLINK20", "1")
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.config.errors import InputError
from mission.viewer.check import check_run_files
from tests.cycle_records import cycle_lines

SHAPE = (4, 3, 2)


def _tlog(records: int) -> bytes:
    """``records`` SIM_STATE packets of vehicle 1, each behind its tlog timestamp."""
    link = mavlink2.MAVLink(None, srcSystem=1, srcComponent=1)
    out = b""
    for n in range(records):
        message = link.sim_state_encode(*([0.0] * 21), lat_int=0, lon_int=0)
        out += struct.pack(">Q", 1_000_000 * n) + message.pack(link)
    return out


def _run(tmp_path: Path, tlog: bytes, records: bytes) -> Path:
    run = tmp_path / "run"
    (run / "g").mkdir(parents=True)
    (run / "gcs.tlog").write_bytes(tlog)
    (run / "records.jsonl").write_bytes(records)
    np.save(run / "g" / "G_initial.npy", np.ones(SHAPE))
    return run


CYCLES = cycle_lines([0.5 * k for k in range(1, 5)])


def test_a_whole_run_passes_without_a_word(tmp_path):
    assert check_run_files(_run(tmp_path, _tlog(8), CYCLES), SHAPE, {"control_cycles": 4}) == []


@pytest.mark.parametrize(
    ("tlog", "records", "snapshot", "expected"),
    [
        (os.urandom(5000), CYCLES, None, "gcs.tlog: holds no vehicle message"),
        (_tlog(8), os.urandom(300).replace(b"\n", b" ") + b"\n", None, "line 1: not a control"),
        (_tlog(8), CYCLES + b"[1, 2]\n", None, "line 5: not a control cycle's record"),
        (_tlog(8), b"", None, "records.jsonl: holds no control cycle's record"),
        (_tlog(8), CYCLES, os.urandom(4000), "G_20.npy: not a G snapshot"),
        (_tlog(8), CYCLES, np.ones(7), "G_20.npy: not a G snapshot of this map"),
        (_tlog(8), CYCLES, np.full(SHAPE, np.nan), "G_20.npy: not a G snapshot (values"),
    ],
    ids=["random-tlog", "random-records", "records-not-objects", "no-records", "random-g",
         "g-shape", "g-nan"],
)  # fmt: skip
def test_a_file_that_is_not_a_runs_is_refused(tmp_path, tlog, records, snapshot, expected):
    run = _run(tmp_path, tlog, records)
    if isinstance(snapshot, bytes):
        (run / "g" / "G_20.npy").write_bytes(snapshot)
    elif snapshot is not None:
        np.save(run / "g" / "G_20.npy", snapshot)
    with pytest.raises(InputError) as caught:
        check_run_files(run, SHAPE, {})
    assert expected in str(caught.value) and "\n" not in str(caught.value)


def test_files_cut_short_are_shown_up_to_the_cut_with_a_warning(tmp_path):
    tlog = _tlog(8)
    run = _run(tmp_path, tlog[:-20], CYCLES[:-3])
    warnings = check_run_files(run, SHAPE, {"control_cycles": 9})
    assert len(warnings) == 3
    assert "gcs.tlog: cut in a record" in warnings[0] and "the view ends there" in warnings[0]
    assert "records.jsonl: its last line is cut" in warnings[1]
    assert "3 cycles where summary.json records 9" in warnings[2]
    tlog_then_garbage = _run(tmp_path / "b", tlog + os.urandom(64).replace(b"\xfd", b"\0"), CYCLES)
    (warning,) = check_run_files(tlog_then_garbage, SHAPE, {})
    assert f"not MAVLink after byte {len(tlog):,}" in warning
