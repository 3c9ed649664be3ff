"""How close a run came, from the truth in its tlog: the closest approach of every pair of UAVs,
each UAV's least clearance from the structure and the ground, the control cycles at which a
margin was broken, the contacts the vehicles reported, the pairs and vehicles whose truth
touched (whether or not a vehicle said so: a run with ``stop_on_crash`` false flies on; a
flying quadrotor's rotor rims and frame, :mod:`~mission.analysis.body_clearance`, a kinematic
point's sphere), and the worst moments.

Between two truth samples each vehicle is taken to fly straight (as it does in a step): a pair's
closest approach over the interval is exact for that motion
(:func:`~mission.world.proximity.closest_approach`), and clearance is sampled along the segment
every quarter of a body radius, as the vehicles' own contact detection does.
"""

from __future__ import annotations

import itertools
from typing import Any, Protocol

import numpy as np

from mission.analysis.body_clearance import attitudes_at, body_touches
from mission.world.contact_body import ContactBody
from mission.world.model import World
from mission.world.proximity import StructureProximity, closest_approach, segment_points


class RunTrace(Protocol):
    """What this module reads of :class:`mission.analysis.metrics.RunTrace` (which calls it)."""

    truth: dict[tuple[int, float], np.ndarray]
    attitudes: dict[tuple[int, float], np.ndarray]
    contacts: list[dict[str, Any]]

    @property
    def cycle_times(self) -> list[float]: ...

    def truth_at(self, system: int, times: list[float]) -> tuple[np.ndarray, np.ndarray]: ...


def _name(system: int) -> str:
    return "work" if system == 1 else f"support-{system - 1}"


def _moment(time_s: float, who: str, distance: float, where: np.ndarray) -> dict[str, Any]:
    return {
        "t": round(float(time_s), 3),
        "who": who,
        "distance_m": round(float(distance), 4),
        "at_m": [round(float(v), 3) for v in where],
    }


def _common_track(trace: RunTrace, systems: list[int]) -> tuple[np.ndarray, dict[int, np.ndarray]]:
    """Every vehicle's truth at the union of their sample times (interpolated where known)."""
    times = np.array(sorted({t for s, t in trace.truth if s in systems}))
    tracks = {}
    for system in systems:
        positions, known = trace.truth_at(system, list(times))
        positions[~known] = np.nan
        tracks[system] = positions
    return times, tracks


def pair_approaches(times: np.ndarray, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, list]:
    """Per interval between samples, the closest approach of two tracks and its moment
    (time, position of a); NaN where either track is unknown."""
    least = np.full(max(len(times) - 1, 0), np.nan)
    moments: list = [None] * len(least)
    known = ~(np.isnan(a).any(axis=1) | np.isnan(b).any(axis=1))
    for i in range(len(least)):
        if not (known[i] and known[i + 1]):
            continue
        distance, fraction = closest_approach(a[i], a[i + 1], b[i], b[i + 1])
        least[i] = distance
        moments[i] = (
            times[i] + fraction * (times[i + 1] - times[i]),
            a[i] + fraction * (a[i + 1] - a[i]),
        )
    return least, moments


def track_clearance(
    proximity: StructureProximity, times: np.ndarray, track: np.ndarray, spacing_m: float
) -> tuple[float, float, np.ndarray]:
    """(least clearance from the structure and the ground, its time, where) along a track."""
    best = (np.inf, np.nan, np.full(3, np.nan))
    known = ~np.isnan(track).any(axis=1)
    segments = [
        (i, segment_points(track[i], track[i + 1], spacing_m))
        for i in range(len(times) - 1)
        if known[i] and known[i + 1]
    ]
    if not segments:
        return best
    # every segment's points in one query (a point's clearance does not depend on the others)
    all_gaps = proximity.clearance(np.vstack([points for _, points in segments]))
    start = 0
    for i, points in segments:
        gaps = all_gaps[start : start + len(points)]
        start += len(points)
        j = int(np.argmin(gaps))
        if gaps[j] < best[0]:
            when = times[i] + (times[i + 1] - times[i]) * j / max(len(points) - 1, 1)
            best = (float(gaps[j]), float(when), points[j])
    return best


def _bodies_touching(
    trace: RunTrace,
    world: World,
    proximity: StructureProximity,
    times: np.ndarray,
    tracks: dict[int, np.ndarray],
) -> list[str]:
    """The flying vehicles whose rotor rims or frame touched the structure or the ground."""
    body = ContactBody.of(world.scenario.vehicle.multicopter)
    touching = []
    for system, track in tracks.items():
        attitudes = attitudes_at(trace.attitudes, system, times)
        if body_touches(proximity, body, (times, track, attitudes)):
            touching.append(_name(system))
    return sorted(touching)


def safety_metrics(trace: RunTrace, world: World) -> dict[str, Any]:
    """The ``safety`` block of summary.json."""
    scenario = world.scenario
    radius = scenario.vehicle.radius_m
    separation, clearance = scenario.control.min_separation_m, scenario.control.clearance_m
    systems = sorted({s for s, _ in trace.truth})
    times, tracks = _common_track(trace, systems)
    cycles = np.array(trace.cycle_times)
    approaches, worst_pair = {}, None
    below_separation = np.zeros(len(cycles), dtype=bool)
    for a, b in itertools.combinations(systems, 2):
        least, moments = pair_approaches(times, tracks[a], tracks[b])
        who = f"{_name(a)}/{_name(b)}"
        if not np.isfinite(least).any():
            continue
        i = int(np.nanargmin(least))
        approaches[who] = round(float(least[i]), 4)
        if worst_pair is None or least[i] < worst_pair["distance_m"]:
            worst_pair = _moment(moments[i][0], who, least[i], moments[i][1])
        at_cycles = np.linalg.norm(
            trace.truth_at(a, list(cycles))[0] - trace.truth_at(b, list(cycles))[0], axis=1
        )
        below_separation |= at_cycles < separation
    proximity = StructureProximity(world.structure)
    clearances, worst_clear = {}, None
    below_clearance = np.zeros(len(cycles), dtype=bool)
    for system in systems:
        least, when, where = track_clearance(proximity, times, tracks[system], radius / 4)
        if not np.isfinite(least):
            continue
        clearances[_name(system)] = round(least, 4)
        if worst_clear is None or least < worst_clear["distance_m"]:
            worst_clear = _moment(when, _name(system), least, where)
        positions, known = trace.truth_at(system, list(cycles))
        gaps = np.full(len(cycles), np.inf)
        gaps[known] = proximity.clearance(positions[known])
        below_clearance |= gaps < clearance
    touching_pairs = sorted(p for p, d in approaches.items() if d < 2 * radius)
    touching_vehicles = sorted(v for v, d in clearances.items() if d < radius)
    if scenario.vehicle.dynamics == "multicopter":  # its rims and frame, not the sphere
        touching_vehicles = _bodies_touching(trace, world, proximity, times, tracks)
    return {
        "radius_m": radius,
        "min_separation_m": separation,
        "clearance_m": clearance,
        "closest_approach_m": approaches,
        "least_clearance_m": clearances,
        "cycles_below_separation": int(below_separation.sum()),
        "cycles_below_clearance": int(below_clearance.sum()),
        "closest_approach_min_m": min(approaches.values(), default=None),
        "least_clearance_min_m": min(clearances.values(), default=None),
        # by time, then reporter: two vehicles that touch report in either order
        "contacts": sorted(trace.contacts, key=lambda c: (c["t"], c["vehicle"], c["with"])),
        "contacts_reported": len(trace.contacts),
        "touching_pairs": touching_pairs,
        "touching_vehicles": touching_vehicles,
        "touching": len(touching_pairs) + len(touching_vehicles),
        "worst_approach": worst_pair,
        "worst_clearance": worst_clear,
    }
