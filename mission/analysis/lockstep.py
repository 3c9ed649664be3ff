"""Whether a lockstep run kept its lockstep, from what its processes counted.

Lockstep is deterministic as long as no wall-clock timeout fires (docs/development.md lists
every place timing could enter a decision): a vehicle that waits more than
``lockstep_timeout_wall_s`` for its tick steps alone on its old setpoint (an *auto step*), a
support that waits more than ``truth_timeout_wall_s`` for the work UAV's truth extrapolates it
(a *truth wait timed out*), and the ground station, after ``step_timeout_wall_s`` without a
vehicle's step, goes on without it (a *late step*). Each vehicle counts its own in the last
line of its log, the ground station its own in link.json; a run where any is not zero says
it may not reproduce.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

# vehicle_sim.server.VehicleServer.summary's words (tested against a real run)
_COUNTS = re.compile(r"auto steps (\d+), truth waits timed out (\d+)")


def lockstep_integrity(vehicle_logs: dict[str, Path], link: dict[str, Any] | None) -> dict:
    """``exact`` (every count zero and every vehicle's counts read), the counts summed over
    the vehicles, and the vehicles whose counts could not be read (if any)."""
    auto_steps = truth_waits = 0
    unread = []
    for name, log in vehicle_logs.items():
        try:
            found = _COUNTS.findall(log.read_text(encoding="utf-8", errors="replace"))
        except OSError:
            found = []
        if not found:
            unread.append(name)
            continue
        auto_steps += int(found[-1][0])
        truth_waits += int(found[-1][1])
    late_steps = int((link or {}).get("late_steps") or 0)
    integrity: dict[str, Any] = {
        "exact": not (auto_steps or truth_waits or late_steps or unread),
        "auto_steps": auto_steps,
        "truth_waits_timed_out": truth_waits,
        "late_steps": late_steps,
    }
    if unread:
        integrity["unread_vehicles"] = unread
    return integrity


def integrity_note(summary: dict[str, Any]) -> str:
    """What the run's one line adds where its lockstep was not exact ('' where it was)."""
    integrity = summary.get("lockstep")
    if not integrity or integrity.get("exact"):
        return ""
    counts = ", ".join(
        f"{key.replace('_', ' ')} {integrity[key]}"
        for key in ("auto_steps", "truth_waits_timed_out", "late_steps")
        if integrity.get(key)
    )
    unread = integrity.get("unread_vehicles")
    if unread:
        counts = ", ".join(filter(None, [counts, f"no counts from {', '.join(unread)}"]))
    return f"; NOT exact lockstep ({counts}): it may not reproduce"
