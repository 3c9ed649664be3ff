"""A finished run whose ``records.jsonl`` was damaged (cut, emptied, doubled, a foreign line):
``mission analyze`` refuses it on one line naming the file, exit status 2, its summary.json
byte for byte as it was; ``mission view --save`` refuses it the same way and writes no
recording, except a file cut short, which it shows up to the cut with a warning."""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from pathlib import Path

import pytest

from tests.cycle_records import cycle_record
from tests.processes import mission

pytestmark = pytest.mark.slow  # a whole run (the session's short run) read again per case


def _lines(data: bytes) -> list[bytes]:
    return data.splitlines(keepends=True)


def _replace_field(field: str, value: object) -> Callable[[bytes], bytes]:
    def damage(data: bytes) -> bytes:
        lines = _lines(data)
        record = json.loads(lines[3])
        record[field] = value
        lines[3] = json.dumps(record).encode() + b"\n"
        return b"".join(lines)

    return damage


def _foreign(line: bytes) -> Callable[[bytes], bytes]:
    return lambda data: b"".join([*_lines(data)[:3], line + b"\n", *_lines(data)[3:]])


DAMAGE = {
    "cut": (lambda data: b"".join(_lines(data)[: len(_lines(data)) * 2 // 5]), "cut short?"),
    "emptied": (lambda data: b"", "control cycle"),
    "doubled": (lambda data: data + data, "does not follow the line before's"),
    "a-list": (_foreign(b"[1, 2, 3]"), "line 4: not a control cycle's record"),
    "null": (_foreign(b"null"), "line 4: not a control cycle's record"),
    "an-object": (_foreign(b'{"x": 1}'), "has no 't'"),
    "time-a-word": (_foreign(json.dumps(cycle_record("soon")).encode()), "t: expected a time"),
    "undecodable": (_foreign(b"\xff\xfe\x00garbage"), "is not JSON"),
    "time-1e300": (_replace_field("t", 1e300), "t: expected a time"),
    "xhat-a-string": (_replace_field("xhat", "here"), "xhat: expected 3 finite numbers"),
    "roles-a-number": (_replace_field("roles", 5), "roles: expected an object"),
    # of another run, or edited (found by a red team)
    "nested-deep": (_foreign(b"[" * 200_000 + b"]" * 200_000), "nested too deeply"),
    "a-support-not-flown": (
        _replace_field("consistent", ["support-9"]),
        "'support-9' is no support",
    ),
    "a-role-never-given": (_replace_field("roles", {"roles": {"support-1": "pilot"}}), "'pilot'"),
    "a-waypoint-not-flown": (_replace_field("arrived", 999), "arrived: waypoint 999"),
    "off-the-grid": (_replace_field("t", 1.75), "off the control period's grid"),
    "a-line-deleted": (
        lambda data: b"".join(_lines(data)[:3] + _lines(data)[4:]),
        "a line deleted?",
    ),
    "an-empty-mpc-path": (
        _replace_field("mpc", {"support-1": {"status": "x", "ms": 1.0, "path": []}}),
        "expected at least one item",
    ),
}


@pytest.fixture(scope="module")
def finished(short_run) -> Path:
    return short_run[0]


@pytest.mark.parametrize("case", sorted(DAMAGE))
def test_damaged_records_are_refused_and_the_summary_kept(finished, tmp_path, case):
    damage, expected = DAMAGE[case]
    copy = tmp_path / "run"
    shutil.copytree(finished, copy)
    records = copy / "records.jsonl"
    records.write_bytes(damage(records.read_bytes()))
    summary = (copy / "summary.json").read_bytes()
    recording = tmp_path / "v.rrd"
    for command in (["analyze", str(copy)], ["view", str(copy), "--save", str(recording)]):
        result = mission(*command)
        lines = result.stderr.strip().splitlines()
        if command[0] == "view" and case == "cut":
            assert result.returncode == 0 and "warning:" in lines[0] and "cut short?" in lines[0]
            assert recording.stat().st_size > 0
            continue
        assert result.returncode == 2, (command, result.stderr)
        assert len(lines) == 1 and "records.jsonl" in lines[0] and expected in lines[0], lines
        assert (copy / "summary.json").read_bytes() == summary
        assert not recording.exists()
