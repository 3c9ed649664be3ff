"""One benchmark figure and its target."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class BenchResult:
    """One measured figure and its target."""

    name: str
    value: float
    unit: str
    target: str
    ok: bool | None  # None: a reference figure with no target
