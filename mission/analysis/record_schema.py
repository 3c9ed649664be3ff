"""What a control cycle's record (a line of the ground station's ``records.jsonl``) must hold
to be read: every field the analysis and the view use, of the type the ground station writes
(:mod:`ground_station.records`). A record that is not so is refused where a finished run is
read (``mission analyze``, ``mission view``) and skipped where a live one is; the file as a
whole must hold its cycles in time order (a doubled file does not).

A problem is said as text (``"xhat: expected 3 finite numbers"``); None means readable.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from typing import Any

MAX_TIME_S = 1e7  # a cycle's time, s: no run lasts months (1e300 overflowed the view)

Check = Callable[[Any], str | None]


def _number(value: Any) -> str | None:
    finite = isinstance(value, int | float) and not isinstance(value, bool)
    return None if finite and math.isfinite(value) else "expected a finite number"


def _time(value: Any) -> str | None:
    if _number(value) is not None or not 0 <= value <= MAX_TIME_S:
        return f"expected a time in [0, {MAX_TIME_S:g}] s"
    return None


def _count(value: Any) -> str | None:
    ok = isinstance(value, int) and not isinstance(value, bool) and value >= 0
    return None if ok else "expected a whole number, 0 or more"


def _flag(value: Any) -> str | None:
    return None if isinstance(value, bool) else "expected true or false"


def _text(value: Any) -> str | None:
    return None if isinstance(value, str) else "expected a string"


def _point(value: Any) -> str | None:
    ok = isinstance(value, list) and len(value) == 3 and all(_number(v) is None for v in value)
    return None if ok else "expected 3 finite numbers"


def _optional(check: Check) -> Check:
    return lambda value: None if value is None else check(value)


def _list_of(check: Check) -> Check:
    def checked(value: Any) -> str | None:
        if not isinstance(value, list):
            return "expected a list"
        problems = (check(item) for item in value)
        return next((f"an item: {p}" for p in problems if p is not None), None)

    return checked


def _map_of(check: Check) -> Check:
    def checked(value: Any) -> str | None:
        if not isinstance(value, dict):
            return "expected an object"
        for key, item in value.items():
            problem = check(item)
            if problem is not None:
                return f"{key}: {problem}"
        return None

    return checked


def _object(required: dict[str, Check], optional: dict[str, Check] | None = None) -> Check:
    def checked(value: Any) -> str | None:
        if not isinstance(value, dict):
            return "expected an object"
        for key, check in required.items():
            if key not in value:
                return f"has no {key!r}"
            problem = check(value[key])
            if problem is not None:
                return f"{key}: {problem}"
        for key, check in (optional or {}).items():
            problem = check(value[key]) if key in value else None
            if problem is not None:
                return f"{key}: {problem}"
        return None

    return checked


def _non_empty(check: Check) -> Check:
    return lambda value: "expected at least one item" if value == [] else check(value)


_SOLVE = _object(  # an MPC's path holds its horizon's points: never none (horizon_steps >= 1)
    {"status": _text, "ms": _number, "path": _non_empty(_list_of(_point))},
    {"resolved": _optional(_flag)},
)
_INTEGRITY = _object(
    {
        "excluded": _list_of(_text),
        "withheld": _list_of(_text),
        "ambiguous": _list_of(_text),
        "events": _list_of(_object({"support": _text, "kind": _text})),
        "protection_m": _map_of(_optional(_number)),
    },
    {"statistics": _map_of(_map_of(_number))},
)
_ROLES = _object({"roles": _map_of(_text)})
_OWN_FIX = _object({"reason": _text})

RECORD = _object(
    {
        "t": _time,
        "k": _count,
        "xhat": _point,
        "blind": _flag,
        "fallback": _flag,
        "consistent": _list_of(_text),
        "contributing": _list_of(_text),
        "yhat": _map_of(_point),
        "beta": _map_of(_optional(_number)),
        "arrived": _optional(_count),
        "mpc": _map_of(_SOLVE),
        "cycle_ms": _number,
    },
    {
        "own_fix": _OWN_FIX,
        "roles": _ROLES,
        "integrity": _INTEGRITY,
        "age_ms": _map_of(_list_of(_optional(_number))),
    },
)


def record_problem(record: Any) -> str | None:
    """What keeps ``record`` from being read as a control cycle's record (None: nothing)."""
    return RECORD(record)


def parse_record(line: bytes | str) -> tuple[dict[str, Any] | None, str | None]:
    """(the record, None) or (None, why the line is not one)."""
    try:
        record = json.loads(line)
    except ValueError:  # UnicodeDecodeError included
        return None, "is not JSON"
    except RecursionError:
        return None, "is nested too deeply to be a record"
    problem = record_problem(record)
    return (record, None) if problem is None else (None, problem)
