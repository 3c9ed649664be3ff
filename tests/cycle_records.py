"""A control cycle's record as the ground station writes it (records.jsonl), for tests that
build run folders by hand."""

from __future__ import annotations

import json
from typing import Any


def cycle_record(t: float, **fields: Any) -> dict[str, Any]:
    """The record of a cycle at ``t`` with one support, ``fields`` replacing or adding."""
    record = {
        "t": t,
        "k": 0,
        "xhat": [0.0, 0.0, 7.0],
        "blind": False,
        "fallback": False,
        "consistent": ["support-1"],
        "contributing": ["support-1"],
        "yhat": {"support-1": [0.0, -10.0, 7.0]},
        "beta": {"support-1": 0.5},
        "arrived": None,
        "g_updated_voxels": 1,
        "mpc": {
            "support-1": {"status": "ok", "ms": 1.0, "resolved": False, "path": [[0.0, 0.0, 7.0]]}
        },
        "cycle_ms": 2.0,
    }
    record.update(fields)
    return record


def cycle_lines(times: list[float]) -> bytes:
    """Whole lines of the records of cycles at ``times``."""
    return b"".join(json.dumps(cycle_record(t)).encode() + b"\n" for t in times)
