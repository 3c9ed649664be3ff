"""What the integrity monitor did in a run, judged against what only the simulation knows:
summary.json's ``integrity`` block (where the monitor was on).

From the ground station's records: each exclusion (its test, the bias it saw, the test's
minimal detectable bias), restoration and receiver call, and the cycles each support was
excluded or withheld. From the tlog's truth and the vehicles' events:

- a **lying fault** is a window in which a support's receiver gave a wrong fix: a glitch
  parameter (``SIM_GPS1_GLTCH_X/Y/Z``) away from 0, or a GNSS failure that reports a fix
  (``stuck``, ``wrong``, ``delayed``); ``off`` and ``garbage`` give no fix to test;
- **time to detect**: from a fault's start to the first cycle at which its support was
  excluded (0 where it was excluded already); a fault during which its support was never
  excluded is a **missed detection**;
- an **integrity event** is a cycle at which an estimate's true error (the work UAV's xhat,
  or the estimate a support was sent) exceeded its protection radius;
- a **false alarm** is an exclusion with no lying fault on that support and no multipath
  bias on its fix: no zone within ``ZONE_TOLERANCE_M`` of its true position (SIM_STATE's 1e-7
  degrees are 1.1 cm, and an MPC keeps a support on a zone's face) and, where the multipath
  comes from the structure's geometry, a fix whose true error is below ``detectable_bias_m``
  (the motion test's open-sky minimal detectable bias, as ``gnss_error_steps`` counts); an
  exclusion of a biased fix (a real bias, if often below the test's minimal detectable bias in
  its worst direction) is a **zone exclusion**, the key's name from when zones were the only
  multipath.
"""

from __future__ import annotations

from collections import defaultdict
from typing import Any

import numpy as np

from mission.analysis.gnss_errors import detectable_bias_m
from mission.analysis.trace import RunTrace
from mission.link.vehicle_identity import VehicleIdentity
from mission.world.model import World

ZONE_TOLERANCE_M = 0.05  # a zone's box this much wider when judging a false alarm
GLITCH_PARAMETERS = ("SIM_GPS1_GLTCH_X", "SIM_GPS1_GLTCH_Y", "SIM_GPS1_GLTCH_Z")
LYING_FAILURES = ("gps stuck", "gps wrong", "gps delayed")


def integrity_metrics(
    trace: RunTrace, records: list[dict[str, Any]], world: World, events: list[dict[str, Any]]
) -> dict[str, Any] | None:
    """The ``integrity`` block (None where no record has the monitor's verdict)."""
    verdicts = [(r["t"], r["integrity"]) for r in records if "integrity" in r]
    if not verdicts:
        return None
    end_s = verdicts[-1][0]
    faults = lying_faults(events, end_s)
    excluded_at: dict[str, list[float]] = defaultdict(list)
    withheld: dict[str, int] = defaultdict(int)
    exclusions, restorations, receivers = [], 0, 0
    for t, verdict in verdicts:
        for name in verdict["excluded"]:
            excluded_at[name].append(t)
        for name in verdict["withheld"]:
            withheld[name] += 1
        for event in verdict["events"]:
            if event["kind"] == "excluded":
                exclusions.append((t, event))
            restorations += event["kind"] == "restored"
            receivers += event["kind"] == "receiver"
    detection = _detections(faults, excluded_at)
    false_alarms, in_zones = _unfaulted(trace, world, exclusions, faults)
    return {
        "exclusions": len(exclusions),
        "restorations": restorations,
        "receiver_calls": receivers,
        "excluded_cycles": {name: len(times) for name, times in sorted(excluded_at.items())},
        "withheld_cycles": dict(sorted(withheld.items())),
        "ambiguous_cycles": sum(1 for _, v in verdicts if v["ambiguous"]),
        "lying_faults": sum(len(windows) for windows in faults.values()),
        "detected_faults": len(detection["delays"]),
        "missed_detections": detection["missed"],
        "time_to_detect_s": detection["delays"][0] if detection["delays"] else None,  # the first
        "times_to_detect_s": detection["delays"],
        "false_alarms": false_alarms,
        "zone_exclusions": in_zones,
        "protection": protection_against_truth(trace, verdicts),
    }


def lying_faults(events: list[dict[str, Any]], end_s: float) -> dict[str, list[list[float]]]:
    """Per support, the [start, end] windows in which its receiver lied; windows that touch
    (a ramp of settings, each starting as the last ends) are one."""
    changes = []
    for event in events:
        vehicle, what = event["vehicle"], event["event"]
        name, _, value = what.partition("=")
        if name in GLITCH_PARAMETERS:
            changes.append((event["t"], _nonzero(value), (vehicle, name)))
        elif what.startswith("gps "):
            changes.append((event["t"], what in LYING_FAILURES, (vehicle, "gps")))
    active: dict[tuple[str, str], float] = {}
    windows: dict[str, list[list[float]]] = defaultdict(list)
    for t, starts, key in sorted(changes, key=lambda c: (c[0], c[1])):  # ends first
        if key in active and not starts:
            windows[key[0]].append([active.pop(key), t])
        elif starts and key not in active:
            active[key] = t
    for (vehicle, _), start in active.items():
        windows[vehicle].append([start, end_s])
    return {vehicle: _merged(spans) for vehicle, spans in windows.items()}


def _merged(spans: list[list[float]]) -> list[list[float]]:
    merged: list[list[float]] = []
    for start, end in sorted(spans):
        if merged and start <= merged[-1][1] + 1e-9:
            merged[-1][1] = max(merged[-1][1], end)
        else:
            merged.append([start, end])
    return merged


def _nonzero(value: str) -> bool:
    try:
        return float(value) != 0.0
    except ValueError:
        return False


def _detections(
    faults: dict[str, list[list[float]]], excluded_at: dict[str, list[float]]
) -> dict[str, Any]:
    delays: list[float] = []
    missed = 0
    for name, windows in faults.items():
        times = excluded_at.get(name, [])
        for start, end in windows:
            during = [t for t in times if start <= t <= end]
            if during:
                delays.append(round(during[0] - start, 3))
            else:
                missed += 1
    return {"delays": delays, "missed": missed}


def _unfaulted(
    trace: RunTrace,
    world: World,
    exclusions: list[tuple[float, dict[str, Any]]],
    faults: dict[str, list[list[float]]],
) -> tuple[int, int]:
    """(false alarms, exclusions of a biased fix) among the exclusions with no lying fault on
    the support: those whose fix no multipath biased (no zone at its true position and, with
    multipath from geometry, a true error within the detectable bias), and the others."""
    false_alarms = in_zones = 0
    geometry = world.scenario.world.gnss.multipath != "zones"
    threshold = detectable_bias_m(world) if geometry else np.inf
    period_s = 1.0 / world.scenario.vehicle.sensor_hz
    listed: dict[int, list[float]] = defaultdict(list)
    for system, t in sorted(trace.fixes):
        listed[system].append(t)
    fix_times = {system: np.array(times) for system, times in listed.items()}
    for t, event in exclusions:
        name = event["support"]
        if any(start <= t <= end for start, end in faults.get(name, [])):
            continue
        system = VehicleIdentity.parse(name).system_id
        truth, known = trace.truth_at(system, [t])
        times = fix_times.get(system, np.empty(0))
        fix = _fix_at(trace, times, system, t, period_s) if geometry else None
        biased = bool(known[0]) and (
            _near_a_zone(world, truth[0])
            or (fix is not None and float(np.linalg.norm(fix - truth[0])) > threshold)
        )
        in_zones += biased
        false_alarms += not biased
    return false_alarms, in_zones


def protection_against_truth(
    trace: RunTrace, verdicts: list[tuple[float, dict[str, Any]]]
) -> dict[str, dict[str, Any]]:
    """Per estimate (work, and the supports pooled): the protection radius's median and p95,
    the true error's median, and the integrity events (error beyond the radius)."""
    pairs: dict[str, list[tuple[float, float]]] = defaultdict(list)
    for t, verdict in verdicts:
        for name, radius in (verdict.get("protection_m") or {}).items():
            if radius is None:
                continue
            error = _true_error(trace, name, t)
            if error is not None:
                pairs["work" if name == "work" else "supports"].append((radius, error))
    found = {}
    for group, values in sorted(pairs.items()):
        radii, errors = np.array(values).T
        found[group] = {
            "radius_median_m": round(float(np.median(radii)), 3),
            "radius_p95_m": round(float(np.percentile(radii, 95)), 3),
            "error_median_m": round(float(np.median(errors)), 3),
            "integrity_events": int(np.sum(errors > radii)),
            "cycles": len(values),
        }
    return found


def _true_error(trace: RunTrace, name: str, t: float) -> float | None:
    """How far the estimate of ``name`` (work: xhat; a support: the estimate it was sent)
    at cycle ``t`` was from its truth then (None where either is unknown)."""
    system = VehicleIdentity.parse(name).system_id
    estimate = trace.estimates.get(t) if system == 1 else trace.sent_estimates.get((system, t))
    if estimate is None:
        return None
    truth, known = trace.truth_at(system, [t])
    return float(np.linalg.norm(estimate - truth[0])) if known[0] else None


def _fix_at(
    trace: RunTrace, times: np.ndarray, system: int, t: float, period_s: float
) -> np.ndarray | None:
    """The vehicle's latest 3-D fix at or before ``t`` (``times``: its fixes' times, sorted),
    if within one sensor period of it (in real time a fix's time is its receiver's, not the
    cycle's)."""
    index = int(np.searchsorted(times, t + 1e-9, side="right")) - 1
    if index < 0 or times[index] < t - period_s - 1e-9:
        return None
    return trace.fixes[(system, float(times[index]))]


def _near_a_zone(world: World, position: np.ndarray) -> bool:
    """Whether ``position`` lies within ZONE_TOLERANCE_M of a zone with a bias."""
    for zone in world.scenario.world.zones:
        low = np.array(zone.min_m) - ZONE_TOLERANCE_M
        high = np.array(zone.max_m) + ZONE_TOLERANCE_M
        if np.any(zone.offset_m) and np.all((position >= low) & (position <= high)):
            return True
    return False
