"""The benchmark's aggregation: medians over repeats and the verdicts against the targets
(the detached run is replaced by one with known timings; the timings themselves are what
``python -m mission bench`` measures)."""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace

import pytest

from mission import bench


@dataclass
class _Plan:
    solve_ms: float


def _run(solves: list[float], cycles: list[float]) -> SimpleNamespace:
    """A detached run whose cycles each plan one support."""
    outputs = [
        SimpleNamespace(support_plans={"support-1": _Plan(s)}, cycle_ms=c)
        for s, c in zip(solves, cycles)
    ]
    return SimpleNamespace(outputs=outputs)


def test_gcs_rows_are_medians_over_repeats_with_verdicts(monkeypatch):
    import ground_station.detached

    repeats = iter(
        [  # solves (ms) and cycle times (ms) of three repeats of the same run
            _run([1, 2, 3, 4, 100], [10, 10, 10, 30, 30]),
            _run([2, 3, 4, 5, 200], [20, 20, 20, 40, 40]),
            _run([9, 9, 9, 9, 9], [50, 50, 50, 50, 50]),
        ]
    )
    monkeypatch.setattr(
        ground_station.detached, "run_detached", lambda *args, **kwargs: next(repeats)
    )
    monkeypatch.setattr(bench, "_scipy_over_casadi", lambda *args: 12.0)
    rows = {r.name: r for r in bench.bench_ground_station(cycles=5, repeats=3)}
    # per-repeat medians 3, 4, 9 -> 4; p95s (linear) 80.8, 161, 9 -> 80.8; cycles 10, 20, 50 -> 20
    assert rows["support_mpc_solve_ms_median"].value == pytest.approx(4.0)
    assert rows["support_mpc_solve_ms_median"].ok
    assert rows["support_mpc_solve_ms_p95"].value == pytest.approx(80.8)
    assert not rows["support_mpc_solve_ms_p95"].ok
    assert rows["gcs_cycle_ms_median"].value == pytest.approx(20.0)
    assert rows["gcs_cycle_ms_median"].ok
    assert rows["scipy_over_casadi_ratio"].value == 12.0
    assert rows["scipy_over_casadi_ratio"].ok
    with pytest.raises(StopIteration):  # exactly three repeats were run
        next(repeats)
