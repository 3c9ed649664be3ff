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


def format_table(results: list[BenchResult]) -> str:
    """A plain-text table of results."""
    width = max([len("benchmark"), *(len(r.name) for r in results)])
    lines = [f"{'benchmark':<{width}} {'value':>12} {'unit':<8} {'target':<10} ok"]
    lines += [
        f"{r.name:<{width}} {r.value:>12.4g} {r.unit:<8} {r.target:<10} {_verdict(r.ok)}"
        for r in results
    ]
    return "\n".join(lines)


def _verdict(ok: bool | None) -> str:
    return "-" if ok is None else "yes" if ok else "NO"
