"""Reading a finished run's ``records.jsonl``: every whole line a control cycle's record
(:mod:`mission.analysis.record_schema`), in time order; a last line without its newline (the
ground station stopped while writing it) is left out and said."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mission.analysis.record_schema import parse_record
from mission.config.errors import InputError


@dataclass(frozen=True)
class RecordsFile:
    """The records of a file, and whether its last line was cut."""

    records: list[dict[str, Any]]
    cut: bool


def read_records_file(path: Path) -> RecordsFile:
    """The records of ``path``; InputError naming the line of one that is not a record or
    not after the one before (a file doubled, or edited)."""
    try:
        data = path.read_bytes()
    except OSError as error:
        raise InputError(str(path), "", f"cannot be read ({error.strerror})") from None
    lines = data.split(b"\n")
    records: list[dict[str, Any]] = []
    for number, line in enumerate(lines[:-1], start=1):
        record, problem = parse_record(line)
        if record is None:
            raise InputError(
                str(path), f"line {number}", f"not a control cycle's record: {problem}"
            )
        if records and record["t"] <= records[-1]["t"]:
            raise InputError(
                str(path),
                f"line {number}",
                f"t = {record['t']:g} s does not follow the line before's {records[-1]['t']:g} s "
                "(a file doubled or edited?)",
            )
        records.append(record)
    return RecordsFile(records, cut=bool(lines[-1]))


def read_records(path: Path) -> list[dict[str, Any]]:
    """The records of ``path`` (:func:`read_records_file`)."""
    return read_records_file(path).records
