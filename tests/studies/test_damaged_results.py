"""``mission study --report-only`` on a damaged results.csv (a copy of the committed Table 3
study's): each damage refused on one line naming the file and where, exit status 2, and the
report, its figures and tables byte for byte as they were."""

from __future__ import annotations

import shutil
from collections.abc import Callable

import pytest

import mission.cli as mission_cli
from tests.processes import ROOT

STUDY = ROOT / "docs" / "studies" / "table3"


def _cell(column: str, value: str, line: int = 3) -> Callable[[bytes], bytes]:
    """The results with ``column`` of ``line`` (1: the header) set to ``value``."""

    def damage(data: bytes) -> bytes:
        lines = data.decode().split("\n")
        header = lines[0].split(",")
        cells = lines[line - 1].split(",")
        cells[header.index(column)] = value
        lines[line - 1] = ",".join(cells)
        return "\n".join(lines).encode()

    return damage


def _without(column: str) -> Callable[[bytes], bytes]:
    def damage(data: bytes) -> bytes:
        rows = [line.split(",") for line in data.decode().split("\n")]
        at = rows[0].index(column)
        return "".join(",".join(r[:at] + r[at + 1 :]) + "\n" for r in rows if r != [""]).encode()

    return damage


DAMAGE = {
    "not-utf8": (lambda d: d[:500] + b"\xff\xfe" + d[500:], "not UTF-8 text"),
    "cut-last-row": (lambda d: d[:-40], "line 61: has no end of line: cut short?"),
    "extra-cells": (_cell("run_key", "0,x", line=2), "line 2: 92 cells where the header has 91"),
    "a-word-for-a-number": (_cell("multipath_steps_total", "abc"), "line 3, multipath_steps_total"),
    "nan": (_cell("work_error_m.mean", "nan"), "expected a finite number, got nan"),
    "inf": (_cell("completion_time_s", "inf"), "expected a finite number, got inf"),
    "no-scenario-column": (_without("scenario"), "no column scenario"),
    "no-method-column": (_without("method"), "no column method"),
    "a-word-for-a-seed": (_cell("seed", "seven"), "line 3: no run of this study is"),
    "completed-maybe": (_cell("completed", "maybe"), "expected True or False, got 'maybe'"),
    "empty": (lambda d: b"", "is empty"),
    "unknown-point": (_cell("point", "7"), "point 7"),
    "a-row-twice": (lambda d: d + d.split(b"\n", 2)[1] + b"\n", "a second time"),
    # found by a red team
    "a-nul-byte": (_cell("run_key", "ab\0cd"), "line 3: holds a NUL byte"),
    "a-column-twice": (
        lambda d: d.replace(b"completion_time_s", b"control_cycles", 1),
        "the column control_cycles is named twice",
    ),
    "a-huge-time": (_cell("completion_time_s", "1.7e308"), "is no run's"),
    "a-completed-run-without-time": (_cell("completion_time_s", ""), "completion time is missing"),
    "a-cell-of-1-mb": (_cell("run_key", '"' + "x" * 1_000_000 + '"'), "is not CSV a study writes"),
}


@pytest.mark.parametrize("case", sorted(DAMAGE))
def test_a_damaged_results_file_is_refused_and_nothing_rewritten(tmp_path, capsys, case):
    damage, expected = DAMAGE[case]
    study = tmp_path / "table3"
    shutil.copytree(STUDY, study)
    results = study / "results.csv"
    results.write_bytes(damage(results.read_bytes()))
    before = {p: p.read_bytes() for p in sorted(study.rglob("*")) if p.is_file()}
    spec = str(ROOT / "mission" / "studies" / "shipped" / "table3.yaml")
    status = mission_cli.entry_point(["study", spec, "--out", str(study), "--report-only"])
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert status == 2, err
    assert len(lines) == 1 and "results.csv" in lines[0] and expected in lines[0], lines
    assert {p: p.read_bytes() for p in sorted(study.rglob("*")) if p.is_file()} == before


def test_rows_in_another_order_give_the_same_report(tmp_path):
    spec = str(ROOT / "mission" / "studies" / "shipped" / "table3.yaml")
    made = {}
    for name, order in (("as-made", lambda rows: rows), ("reversed", lambda rows: rows[::-1])):
        study = tmp_path / name
        shutil.copytree(STUDY, study)
        header, *rows = (study / "results.csv").read_text().splitlines(keepends=True)
        (study / "results.csv").write_text(header + "".join(order(rows)))
        assert mission_cli.entry_point(["study", spec, "--out", str(study), "--report-only"]) == 0
        made[name] = (study / "report.md").read_bytes(), (study / "table.md").read_bytes()
    assert made["as-made"] == made["reversed"]
