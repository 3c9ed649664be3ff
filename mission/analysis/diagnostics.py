"""Why a run went as it did: how often the fusion let a support in while it was in a zone,
how often S was empty, the work UAV's error with and without a support in a zone, and the time
lost beyond pure flight. From the tlog's truth (which the ground station never sees) and the
ground station's ``records.jsonl``.
"""

from __future__ import annotations

from collections import Counter
from typing import Any

import numpy as np

from mission.analysis.metrics import RunTrace, work_errors, zone_steps
from mission.config.settings import Scenario
from mission.link.plan_files import read_vehicle_waypoints
from mission.world.model import World


def diagnostics(
    trace: RunTrace, records: list[dict[str, Any]], world: World, scenario: Scenario
) -> dict[str, Any]:
    """The ``diagnostics`` block of summary.json."""
    in_zone = {s: set(times) for s, times in zone_steps(trace, world).items()}
    by_time = {r["t"]: r for r in records}
    supports = {}
    for system in trace.supports:
        name = f"support-{system - 1}"
        cycles = sorted(t for t in in_zone.get(system, ()) if t in by_time)
        fused = sum(1 for t in cycles if name in by_time[t]["consistent"])
        supports[name] = {
            "zone_cycles": len(cycles),
            "fused_in_zone": fused,
            "fused_in_zone_rate": round(fused / len(cycles), 4) if cycles else None,
        }
    any_in_zone = set().union(*in_zone.values()) if in_zone else set()
    times, errors = work_errors(trace)
    zone_mask = np.array([t in any_in_zone for t in times], dtype=bool)
    verdicts = [r["own_fix"]["reason"] for r in records if "own_fix" in r]
    own_fix = {"own_fix_cycles": dict(sorted(Counter(verdicts).items()))} if verdicts else {}
    return {
        "supports": supports,
        **own_fix,  # roles.policy dynamic: how often the work UAV's own fix was used, or why not
        "empty_s_cycles": sum(1 for r in records if r.get("fallback")),
        "blind_cycles": sum(1 for r in records if r.get("blind")),
        "work_error_mean_m_support_in_zone": _mean(errors[zone_mask]) if len(times) else None,
        "work_error_mean_m_none_in_zone": _mean(errors[~zone_mask]) if len(times) else None,
        "time_beyond_flight_s": time_beyond_flight(trace, scenario),
    }


def time_beyond_flight(trace: RunTrace, scenario: Scenario) -> float | None:
    """Completion time minus the time to fly the work UAV's path at its top speed (from where
    it started, through every waypoint of its plan file); None if the run did not complete."""
    if trace.completion is None:
        return None
    times, positions = trace.track(1)
    if not len(times):
        return None
    path = np.vstack([positions[:1], read_vehicle_waypoints(scenario, "work")])
    length = float(np.sum(np.linalg.norm(np.diff(path, axis=0), axis=1)))
    return round(trace.completion - length / scenario.control.s_max_work_m_s, 3)


def _mean(values: np.ndarray) -> float | None:
    return round(float(np.mean(values)), 4) if len(values) else None
