"""A run's decisions as one digest, at a stated precision: what a lockstep run gives again.

The digest hashes every field of every control cycle's record (``records.jsonl``: the
estimates, the consistent set S and the contributing supports, beta_n, arrival, G's update,
each MPC's status, whether it re-solved and its predicted path, the roles and the work UAV's
own fix where a run has them) except the wall-clock ones (the cycle's ``cycle_ms``, each
solve's ``ms``, real time's ``age_ms``), with every number rounded to ``DECIMALS`` decimal
places. The records already hold positions to 0.1 mm; the rounding matters for beta_n, which
they hold at full precision, and whose last bits depend on the order in which a numpy kernel
adds (1e-16 between AVX2 and AVX-512 kernels). A decision that moves moves a position by 0.1 mm
or more, or changes S, beta_n by more than 1e-6 or a status, and so the digest.
"""

from __future__ import annotations

import hashlib
import json
from typing import Any

DECIMALS = 6  # every number, rounded to this many decimal places
WALL_CLOCK_FIELDS = ("cycle_ms", "age_ms")  # of a record
WALL_CLOCK_SOLVE_FIELDS = ("ms",)  # of each MPC's solve
DIGEST_CHARS = 16


def decisions_digest(records: list[dict[str, Any]]) -> str:
    """The first ``DIGEST_CHARS`` hex digits of the sha256 of the records' decisions."""
    canonical = [_decisions(record) for record in records]
    text = json.dumps(canonical, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:DIGEST_CHARS]


def _decisions(record: dict[str, Any]) -> dict[str, Any]:
    kept = {k: v for k, v in record.items() if k not in WALL_CLOCK_FIELDS}
    if isinstance(kept.get("mpc"), dict):
        kept["mpc"] = {
            name: {k: v for k, v in solve.items() if k not in WALL_CLOCK_SOLVE_FIELDS}
            for name, solve in kept["mpc"].items()
        }
    return _rounded(kept)


def _rounded(value: Any) -> Any:
    if isinstance(value, float):
        return round(value, DECIMALS) + 0.0  # + 0.0: -0.0 and 0.0 hash alike
    if isinstance(value, dict):
        return {key: _rounded(inner) for key, inner in value.items()}
    if isinstance(value, list):
        return [_rounded(inner) for inner in value]
    return value
