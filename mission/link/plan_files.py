"""Planned waypoint files of a scenario: writing a plan, reading one back, vehicle homes."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mission.config.errors import InputError
from mission.config.settings import Scenario
from mission.link.waypoints import (
    read_waypoints,
    row_position_enu,
    waypoint_rows_from_enu,
    write_waypoints,
)
from mission.world.frames import GeodeticFrame


@dataclass(frozen=True)
class Plan:
    """Work waypoints (I, 3) and support waypoints (N, I, 3), ENU metres."""

    work: np.ndarray
    supports: np.ndarray


def vehicle_names(supports: int) -> list[str]:
    """'work', 'support-1', ..., 'support-N'."""
    return ["work", *(f"support-{n}" for n in range(1, supports + 1))]


def write_plan(plan: Plan, scenario: Scenario, directory: Path) -> list[Path]:
    """One QGC WPL 110 file per vehicle; returns the paths written."""
    frame = GeodeticFrame(scenario.world.anchor)
    directory.mkdir(parents=True, exist_ok=True)
    tolerance = scenario.control.arrival_tol_m
    paths = []
    for name, points in zip(vehicle_names(len(plan.supports)), [plan.work, *plan.supports]):
        path = directory / f"{name}.waypoints"
        write_waypoints(path, waypoint_rows_from_enu(points, frame, tolerance))
        paths.append(path)
    return paths


def read_vehicle_waypoints(scenario: Scenario, name: str) -> np.ndarray:
    """ENU positions of a vehicle's planned waypoints (home excluded), from its file."""
    path = Path(scenario.task.waypoints_dir) / f"{name}.waypoints"
    if not path.is_file():
        raise InputError(
            str(path),
            "",
            f"no planned waypoints for {name} (run: python -m "
            f"mission plan {scenario.name} --out DIR)",
        )
    rows = read_waypoints(path)
    frame = GeodeticFrame(scenario.world.anchor)
    return np.array([row_position_enu(row, frame) for row in rows[1:]])


def read_plan(scenario: Scenario) -> Plan:
    """The scenario's planned waypoints for every vehicle."""
    names = vehicle_names(scenario.task.supports)
    work = read_vehicle_waypoints(scenario, names[0])
    supports = np.array([read_vehicle_waypoints(scenario, n) for n in names[1:]])
    return Plan(work=work, supports=supports)
