"""Reading a finished run's ``records.jsonl``: every whole line a control cycle's record
(:mod:`mission.analysis.record_schema`), in time order; a last line without its newline (the
ground station stopped while writing it) is left out and said. Given the run's shape, each
record must also be of that run: its supports' names, its waypoints, cycles on the control
period's grid and, in lockstep, none missing."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mission.analysis.record_schema import parse_record
from mission.config.errors import InputError

ROLE_NAMES = frozenset({"formation", "inspecting", "returning"})  # ground_station/roles
GRID_TOLERANCE_S = 2e-3  # the station writes t to the millisecond


@dataclass(frozen=True)
class RunShape:
    """What a run's records must agree with."""

    supports: int
    waypoints: int  # the work UAV's
    t_cont_s: float
    lockstep: bool  # each cycle one period after the one before

    @property
    def names(self) -> frozenset[str]:
        return frozenset(f"support-{n}" for n in range(1, self.supports + 1))

    @classmethod
    def of(cls, scenario: Any, summary: dict[str, Any]) -> RunShape:
        """The shape of a run of ``scenario`` whose summary.json is ``summary``."""
        return cls(
            scenario.task.supports,
            len(scenario.task.work_waypoints_m),
            scenario.control.t_cont_s,
            summary.get("mode") == "lockstep",
        )


def _named(record: dict[str, Any]) -> list[tuple[str, Any]]:
    """(field, support name) of every support a record names."""
    named = [(f, n) for f in ("consistent", "contributing") for n in record[f]]
    named += [(f, n) for f in ("yhat", "beta", "mpc", "age_ms") for n in record.get(f) or {}]
    named += [("roles", n) for n in (record.get("roles") or {}).get("roles", {})]
    integrity = record.get("integrity") or {}
    named += [
        (f"integrity.{f}", n)
        for f in ("excluded", "withheld", "ambiguous")
        for n in integrity.get(f, [])
    ]
    return named


def shape_problem(record: dict[str, Any], shape: RunShape) -> str | None:
    """Why ``record`` is not one of a run of ``shape`` (None: it may be)."""
    for field, name in _named(record):
        if name not in shape.names:
            return f"{field}: {name!r} is no support of this run ({shape.supports} supports)"
    roles = (record.get("roles") or {}).get("roles", {})
    for name, role in roles.items():
        if role not in ROLE_NAMES:
            return f"roles: {name}'s role {role!r} is none the station gives"
    for field in ("arrived", "k"):
        value = record.get(field)
        if value is not None and value > shape.waypoints:
            return f"{field}: waypoint {value}, of a path of {shape.waypoints}"
    cycles = record["t"] / shape.t_cont_s
    if abs(cycles - round(cycles)) * shape.t_cont_s > GRID_TOLERANCE_S:
        return f"t = {record['t']:g} s is off the control period's grid ({shape.t_cont_s:g} s)"
    return None


@dataclass(frozen=True)
class RecordsFile:
    """The records of a file, and whether its last line was cut."""

    records: list[dict[str, Any]]
    cut: bool


def read_records_file(path: Path, shape: RunShape | None = None) -> RecordsFile:
    """The records of ``path``; InputError naming the line of one that is not a record, not
    of a run of ``shape`` (if given) or not after the one before (a file doubled, or
    edited)."""
    try:
        data = path.read_bytes()
    except OSError as error:
        raise InputError(str(path), "", f"cannot be read ({error.strerror})") from None
    lines = data.split(b"\n")
    records: list[dict[str, Any]] = []
    for number, line in enumerate(lines[:-1], start=1):
        record, problem = parse_record(line)
        if record is not None and shape is not None:
            problem = shape_problem(record, shape)
            record = None if problem is not None else record
        if record is None:
            raise InputError(
                str(path), f"line {number}", f"not a control cycle's record: {problem}"
            )
        if records and shape is not None and shape.lockstep:
            gap = record["t"] - records[-1]["t"]
            if gap > shape.t_cont_s + GRID_TOLERANCE_S:
                raise InputError(
                    str(path),
                    f"line {number}",
                    f"t = {record['t']:g} s comes {gap:g} s after the line before's: a lockstep "
                    f"run records every {shape.t_cont_s:g} s (a line deleted?)",
                )
        if records and record["t"] <= records[-1]["t"]:
            raise InputError(
                str(path),
                f"line {number}",
                f"t = {record['t']:g} s does not follow the line before's {records[-1]['t']:g} s "
                "(a file doubled or edited?)",
            )
        records.append(record)
    if shape is not None and records:
        named = {name for record in records for _, name in _named(record)}
        missing = sorted(shape.names - named)
        if missing:
            raise InputError(
                str(path),
                "",
                f"no record names {missing[0]}: not a run of {shape.supports} supports "
                "(another scenario's?)",
            )
    return RecordsFile(records, cut=bool(lines[-1]))


def read_records(path: Path) -> list[dict[str, Any]]:
    """The records of ``path`` (:func:`read_records_file`)."""
    return read_records_file(path).records
