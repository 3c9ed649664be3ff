"""Every metric of a run's summary.json that its files determine: the tlog's (Table 3's), the
mode and the ages of the measurements the ground station used, the support MPCs' solve times,
the diagnostics and the digest of the decisions, which also read ``records.jsonl``."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from mission.analysis.decisions import decisions_digest
from mission.analysis.diagnostics import diagnostics
from mission.analysis.integrity import integrity_metrics
from mission.analysis.metrics import (
    RunTrace,
    measurement_ages,
    mpc_stats,
    read_tlog,
    trace_metrics,
)
from mission.analysis.records_file import read_records
from mission.analysis.roles import role_metrics
from mission.config.settings import Scenario
from mission.world.model import World


def run_metrics(tlog: Path, scenario: Scenario) -> dict[str, Any]:
    """The tlog's metrics, plus ``mpc_solve_ms`` and ``diagnostics`` where the ground
    station's ``records.jsonl`` lies beside the tlog."""
    return metrics_of(read_tlog(tlog, scenario), World(scenario), tlog.parent, scenario)


def metrics_of(trace: RunTrace, world: World, run_dir: Path, scenario: Scenario) -> dict[str, Any]:
    """:func:`run_metrics` of a tlog already read (``trace``), with the records of
    ``run_dir``: a caller that also plots the run reads the tlog once."""
    metrics = {"mode": trace.mode, **trace_metrics(trace, world)}
    records_file = run_dir / "records.jsonl"
    if records_file.is_file():
        records = read_records(records_file)
        metrics["measurement_age_ms"] = measurement_ages(records)
        metrics["mpc_solve_ms"] = mpc_stats(records)
        metrics["diagnostics"] = diagnostics(trace, records, world, scenario)
        metrics["roles"] = role_metrics(trace, records, world, scenario)
        found = integrity_metrics(trace, records, world, metrics.get("events") or [])
        if found is not None:  # the integrity monitor was on
            metrics["integrity"] = found
        metrics["decisions_digest"] = decisions_digest(records)
    return metrics
