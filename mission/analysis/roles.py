"""Who did what in a run: the ``roles`` block of summary.json.

- ``all_done_s``: when all the inspection work was done, the work UAV's task and every
  support's own inspection waypoints (the work UAV's completion where no support has any);
- ``support_minutes``: minutes of support time in each role (formation, inspecting,
  returning), from the ground station's records;
- ``waypoints_reached``: per UAV, how many of its inspection waypoints it ``reached`` ``of``
  how many (the work UAV's path after the first, where it starts; each support's
  ``task.inspections``);
- ``role_switches``: how many times a support changed role;
- ``work_error_m``: the work UAV's error where the sky gives it a fix (``open``) and where
  the structure hides too many satellites (``shadow``), from the truth.
"""

from __future__ import annotations

from collections import Counter
from typing import Any

from mission.analysis.metrics import RunTrace, work_errors
from mission.analysis.spread import spread
from mission.config.settings import Scenario
from mission.world.model import World

ROLES = ("formation", "inspecting", "returning")


def role_metrics(
    trace: RunTrace, records: list[dict[str, Any]], world: World, scenario: Scenario
) -> dict[str, Any]:
    """The ``roles`` block of summary.json."""
    inspections = {i.vehicle: len(i.waypoints_m) for i in scenario.task.inspections}
    seconds: Counter[str] = Counter()
    switches, last = 0, {}
    supports = trace.supports
    for record in records:
        roles = record.get("roles", {}).get("roles", {})
        for name, role in roles.items():
            seconds[role] += scenario.control.t_cont_s
            switches += role != last.get(name, "formation")
            last[name] = role
        for name in supports:
            if f"support-{name - 1}" not in roles:
                seconds["formation"] += scenario.control.t_cont_s
    reached = records[-1].get("roles", {}).get("next_inspection", {}) if records else {}
    arrivals = len({r["arrived"] for r in records if r.get("arrived") is not None})
    to_reach = {"work": (arrivals, len(scenario.task.work_waypoints_m) - 1)}  # from the first
    to_reach |= {n: (int(reached.get(n, 0)), total) for n, total in sorted(inspections.items())}
    waypoints = {n: {"reached": a, "of": b} for n, (a, b) in to_reach.items()}
    done = trace.inspections_done if inspections else trace.completion
    return {
        "policy": scenario.roles.policy,
        "all_done_s": done,
        "support_minutes": {role: round(seconds[role] / 60, 4) for role in ROLES},
        "waypoints_reached": waypoints,
        "role_switches": switches,
        "work_error_m": _error_by_sky(trace, world),
    }


def _error_by_sky(trace: RunTrace, world: World) -> dict[str, dict[str, float | None]]:
    """The work UAV's error where the sky gives a fix at its true position, and where not."""
    times, errors = work_errors(trace)
    if not len(times):
        return {"open": spread([]), "shadow": spread([])}
    truth, _ = trace.truth_at(1, list(times))
    open_sky = world.gnss.geometry(truth).has_fix
    return {
        "open": spread([float(e) for e in errors[open_sky]]),
        "shadow": spread([float(e) for e in errors[~open_sky]]),
    }
