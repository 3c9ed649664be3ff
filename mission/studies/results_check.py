"""A study's ``results.csv`` checked before a report is written from it (``mission study
--report-only``): UTF-8 text ending in a whole line, a header with the columns a row is found
by, every row as many cells as the header, each naming a run of the study once, ``completed``
true or false, each number the report reads finite and of a size a run can give, a completed
run's completion time given. A file that is not so is refused on one line naming the line and
the column; nothing is written. The rows come back in the study's order, however the file
holds them, so a report does not depend on it."""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path
from typing import Any

from mission.config.errors import InputError
from mission.studies.report import INTEGRITY_METRICS, METRICS, ROLE_METRICS
from mission.studies.results import read_cell
from mission.studies.runkeys import StudyRun

IDENTITY = ("scenario", "point", "method", "seed")
NUMBERS = tuple(column for column, _ in METRICS + ROLE_METRICS + INTEGRITY_METRICS)
MAX_NUMBER = 1e9  # no metric of a run comes near (the largest are step counts, ~10^3)


def checked_results(path: Path, runs: list[StudyRun]) -> list[dict[str, Any]]:
    """The rows of ``path``, each one of ``runs`` (the study's, planned)."""
    text = _text(path)
    if text and not text.endswith("\n"):  # results_csv ends every line
        lines = text.count("\n") + 1
        raise InputError(str(path), f"line {lines}", "has no end of line: cut short?")
    if "\0" in text:
        line = text[: text.index("\0")].count("\n") + 1
        raise InputError(str(path), f"line {line}", "holds a NUL byte: not a results file")
    try:
        return _checked_rows(path, text, runs)
    except csv.Error as error:  # a cell past the csv module's limit, a stray quote
        raise InputError(str(path), "", f"is not CSV a study writes ({error})") from None


def _checked_rows(path: Path, text: str, runs: list[StudyRun]) -> list[dict[str, Any]]:
    reader = csv.reader(io.StringIO(text, newline=""))
    header = next(reader, None)
    if not header:
        raise InputError(str(path), "", "is empty: no header and no row")
    twice = sorted({column for column in header if header.count(column) > 1})
    if twice:
        raise InputError(str(path), "line 1", f"the column {twice[0]} is named twice")
    missing = [column for column in (*IDENTITY, "completed") if column not in header]
    if missing:
        raise InputError(str(path), "line 1", f"no column {', '.join(missing)} in the header")
    order = {(r.scenario_name, r.point, r.method, r.seed): i for i, r in enumerate(runs)}
    planned = order.keys()
    seen: set[tuple] = set()
    rows = []
    for number, cells in enumerate(reader, start=2):
        if len(cells) != len(header):
            raise InputError(
                str(path),
                f"line {number}",
                f"{len(cells)} cells where the header has {len(header)} (cut short or edited?)",
            )
        row = {column: read_cell(cell) for column, cell in zip(header, cells, strict=True)}
        identity = tuple(row[column] for column in IDENTITY)
        if identity not in planned:
            raise InputError(
                str(path), f"line {number}", f"no run of this study is {_named(identity)}"
            )
        if identity in seen:
            raise InputError(str(path), f"line {number}", f"{_named(identity)} a second time")
        seen.add(identity)
        _check_cells(path, number, row)
        rows.append(row)
    if not rows:
        raise InputError(str(path), "", "holds a header and no row")
    return sorted(rows, key=lambda row: order[tuple(row[column] for column in IDENTITY)])


def _text(path: Path) -> str:
    try:
        return path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as error:
        raise InputError(str(path), f"byte {error.start}", "not UTF-8 text") from None
    except OSError as error:
        raise InputError(str(path), "", f"cannot be read ({error.strerror})") from None


def _check_cells(path: Path, number: int, row: dict[str, Any]) -> None:
    completed = row["completed"]
    if not isinstance(completed, bool):
        where = f"line {number}, completed"
        raise InputError(str(path), where, f"expected True or False, got {completed!r}")
    for column in NUMBERS:
        value = row.get(column)
        finite = isinstance(value, int | float) and not isinstance(value, bool)
        if value is not None and not (finite and math.isfinite(value)):
            raise InputError(
                str(path), f"line {number}, {column}", f"expected a finite number, got {value!r}"
            )
        if value is not None and abs(value) > MAX_NUMBER:
            raise InputError(
                str(path), f"line {number}, {column}", f"{value:g} is no run's (edited?)"
            )
    if completed and row.get("completion_time_s") is None:
        where = f"line {number}, completion_time_s"
        raise InputError(str(path), where, "a completed run's completion time is missing")


def _named(identity: tuple) -> str:
    scenario, point, method, seed = identity
    return f"scenario {scenario!r}, point {point!r}, method {method!r}, seed {seed!r}"
