"""Metrics of a run from its tlog alone (plus the scenario's zones), as the paper's Table 3 counts.

- truth: SIM_STATE of each vehicle, grouped by the simulated time the ground station logged;
- the work UAV's estimate: the VISION_POSITION_ESTIMATE the ground station sent it (each one is
  followed by the SET_POSITION_TARGET_LOCAL_NED for the same vehicle, which names it);
- control cycles: the ground station's SYSTEM_TIME clock ticks to the work UAV;
- completion: the ground station's "Mission complete" STATUSTEXT.
"""

from __future__ import annotations

import os
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

os.environ.setdefault("MAVLINK20", "1")
from pymavlink import mavutil

from mission.frames import GeodeticFrame, ned_to_enu
from mission.settings import Scenario
from mission.world import World

GCS_SYSTEM_ID = 255


def analyze_tlog(tlog: Path, scenario: Scenario) -> dict[str, Any]:
    """The tlog-determined metrics of summary.json."""
    world = World(scenario)
    frame = GeodeticFrame(scenario.world.anchor)
    epoch = scenario.run.epoch_unix_s
    truth: dict[tuple[int, float], np.ndarray] = {}
    estimates: dict[float, np.ndarray] = {}
    ticks: set[float] = set()
    completion = None
    pending_estimate: tuple[float, np.ndarray] | None = None
    log = mavutil.mavlink_connection(str(tlog), dialect="ardupilotmega", robust_parsing=True)
    while (message := log.recv_match()) is not None:
        kind = message.get_type()
        t = round(message._timestamp - epoch, 3)
        source = message.get_srcSystem()
        if kind == "SIM_STATE" and source != GCS_SYSTEM_ID:
            truth[(source, t)] = frame.from_degE7(message.lat_int, message.lon_int, message.alt)
        elif source != GCS_SYSTEM_ID:
            continue
        elif kind == "VISION_POSITION_ESTIMATE":
            pending_estimate = (t, ned_to_enu(np.array([message.x, message.y, message.z])))
        elif kind == "SET_POSITION_TARGET_LOCAL_NED":
            if pending_estimate is not None and message.target_system == 1:
                estimates[pending_estimate[0]] = pending_estimate[1]
            pending_estimate = None
        elif kind == "SYSTEM_TIME" and message.time_boot_ms > 0:
            ticks.add(round(message.time_boot_ms / 1000.0, 3))
        elif kind == "STATUSTEXT" and "Mission complete" in message.text and completion is None:
            completion = t
    supports = sorted({s for s, _ in truth if s != 1})
    steps = defaultdict(int)
    for t in sorted(ticks):
        for system in supports:
            position = truth.get((system, t))
            if position is not None and world.in_zone(position[None])[0]:
                steps[f"support-{system - 1}"] += 1
    errors = [
        float(np.linalg.norm(x - truth[(1, t)]))
        for t, x in sorted(estimates.items())
        if (1, t) in truth
    ]
    return {
        "completed": completion is not None,
        "completion_time_s": completion,
        "control_cycles": len(estimates),
        "multipath_steps": {f"support-{s - 1}": steps[f"support-{s - 1}"] for s in supports},
        "multipath_steps_total": int(sum(steps.values())),
        "work_error_m": _stats(errors),
    }


def _stats(values: list[float]) -> dict[str, float | None]:
    if not values:
        return {"mean": None, "p95": None, "max": None}
    return {
        "mean": round(float(np.mean(values)), 4),
        "p95": round(float(np.percentile(values, 95)), 4),
        "max": round(float(np.max(values)), 4),
    }


def mpc_stats(records: Path) -> dict[str, float | None]:
    """Median and p95 of the support-MPC solve times in records.jsonl."""
    import json

    times = [
        m["ms"]
        for line in records.read_text().splitlines()
        for m in json.loads(line)["mpc"].values()
    ]
    if not times:
        return {"median": None, "p95": None}
    return {
        "median": round(float(np.median(times)), 3),
        "p95": round(float(np.percentile(times, 95)), 3),
    }
