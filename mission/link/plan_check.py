"""A scenario's waypoint files checked as the vehicles and the ground station will use them,
before any process starts: what a vehicle would refuse, or fly into, is caught here."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from mission.config.errors import InputError
from mission.link.mission_items import GLOBAL_FRAMES, NAV_POSITION_COMMANDS
from mission.link.waypoints import WaypointRow, read_waypoints, row_position_enu
from mission.world.frames import GeodeticFrame
from mission.world.model import KnownWorld

# a planned file that does not fit the scenario (its structure or its path changed since)
PLAN_AGAIN = "; plan it again (python -m mission plan SCENARIO)"


def check_plan_files(world: KnownWorld, directory: Path, names: Sequence[str]) -> None:
    """Each vehicle's ``<name>.waypoints`` in ``directory``: home and at least one waypoint,
    no more items than a vehicle stores, every row a navigation command in a global frame,
    every position inside the workspace and outside the structure; every support with as many
    waypoints as the work UAV (they pair by index), and the margins kept: every waypoint at
    least ``control.clearance_m`` from the structure and the ground, every two vehicles'
    waypoints of the same index at least ``control.min_separation_m`` apart. The first problem
    raises InputError naming the file and the item."""
    frame = GeodeticFrame(world.scenario.world.anchor)
    counts = {}
    positions: dict[str, np.ndarray] = {}
    for name in names:
        path = Path(directory) / f"{name}.waypoints"
        if not path.is_file():
            raise InputError(str(path), "", f"no waypoint file for {name}")
        rows = read_waypoints(path)
        if len(rows) < 2:
            raise InputError(str(path), "", "needs a home row and at least one waypoint")
        capacity = world.scenario.vehicle.mission_capacity
        if len(rows) > capacity:
            problem = f"{len(rows)} items, more than a vehicle stores (vehicle.mission_capacity "
            raise InputError(str(path), "", problem + f"{capacity})")
        for row in rows:
            _check_row(world, frame, path, row)
        counts[name] = len(rows) - 1
        positions[name] = np.array([row_position_enu(row, frame) for row in rows[1:]])
    work = counts.get("work")
    for name, count in counts.items():
        if work is not None and count != work:
            path = Path(directory) / f"{name}.waypoints"
            problem = f"{count} waypoints, but work.waypoints has {work} (they pair by index)"
            raise InputError(str(path), "", problem)
    _check_margins(world, Path(directory), positions)


def _check_margins(world: KnownWorld, directory: Path, positions: dict[str, np.ndarray]) -> None:
    """The planned paths keep the margins the MPCs will hold the vehicles to."""
    from mission.world.proximity import StructureProximity

    control = world.scenario.control
    if control.clearance_m > 0:
        proximity = StructureProximity(world.structure)
        for name, points in positions.items():
            gaps = proximity.clearance(points)
            worst = int(np.argmin(gaps))
            if gaps[worst] < control.clearance_m - 1e-6:
                problem = (
                    f"{gaps[worst]:.2f} m from the structure or the ground, less than "
                    f"control.clearance_m ({control.clearance_m:g} m)"
                )
                path = str(directory / f"{name}.waypoints")
                raise InputError(path, f"item {worst + 1}", problem + PLAN_AGAIN)
    if control.min_separation_m > 0:
        names = list(positions)
        for i, first in enumerate(names):
            for second in names[i + 1 :]:
                count = min(len(positions[first]), len(positions[second]))
                gaps = np.linalg.norm(positions[first][:count] - positions[second][:count], axis=1)
                worst = int(np.argmin(gaps))
                if gaps[worst] < control.min_separation_m - 1e-6:
                    problem = (
                        f"{gaps[worst]:.2f} m from {second}'s waypoint of the same index, less "
                        f"than control.min_separation_m ({control.min_separation_m:g} m)"
                    )
                    path = str(directory / f"{first}.waypoints")
                    raise InputError(path, f"item {worst + 1}", problem)


def _check_row(world: KnownWorld, frame: GeodeticFrame, path: Path, row: WaypointRow) -> None:
    where = f"item {row.seq}"
    if row.command not in NAV_POSITION_COMMANDS:
        raise InputError(str(path), where, f"command {row.command} is not a waypoint to fly")
    if row.frame not in GLOBAL_FRAMES:
        raise InputError(str(path), where, f"frame {row.frame} is not a global frame")
    position = np.asarray(row_position_enu(row, frame))
    shown = [round(float(v), 2) for v in position]
    problem = world.placement_problem(position)
    if problem is not None:
        raise InputError(str(path), where, f"{shown} (ENU) lies {problem}{PLAN_AGAIN}")


def check_work_waypoints_clear(world: KnownWorld) -> None:
    """The work UAV's path where it can be flown: each waypoint outside the structure and at
    least ``control.clearance_m`` from it (a waypoint file written by hand, not planned)."""
    scenario = world.scenario
    for i, point in enumerate(scenario.task.work_waypoints_m):
        place = np.asarray(point, dtype=float)
        problem = world.placement_problem(place) or world.clearance_problem(place)
        if problem is not None:
            field = f"task.work_waypoints_m[{i}]"
            raise InputError(scenario.source, field, f"{list(point)} lies {problem}")


def check_inspections_placed(world: KnownWorld) -> None:
    """Every support's own inspection waypoint where a vehicle can be (outside the
    structure): the first that is not raises InputError naming the scenario file and field."""
    scenario = world.scenario
    for i, inspection in enumerate(scenario.task.inspections):
        for j, point in enumerate(inspection.waypoints_m):
            place = np.asarray(point, dtype=float)
            problem = world.placement_problem(place) or world.clearance_problem(place)
            if problem is not None:
                field = f"task.inspections[{i}].waypoints_m[{j}]"
                raise InputError(scenario.source, field, f"{list(point)} lies {problem}")


FILE_ROUNDING_M = 0.12  # a waypoint file holds 6 decimals of a degree (about 0.1 m)


def check_work_plan_matches(world: KnownWorld, directory: Path) -> None:
    """The work UAV's waypoint file is the scenario's ``task.work_waypoints_m`` (what the
    planner wrote for it): a path edited in the scenario and not planned again would fly the
    old file's. The first waypoint that differs raises InputError naming the file and item."""
    from mission.link.plan_files import read_vehicle_waypoints

    scenario = world.scenario
    path = Path(directory) / "work.waypoints"
    flown = read_vehicle_waypoints(scenario, "work")
    wanted = np.asarray(scenario.task.work_waypoints_m, dtype=float)
    again = PLAN_AGAIN
    if len(flown) != len(wanted):
        problem = f"{len(flown)} waypoints, the scenario's task.work_waypoints_m {len(wanted)}"
        raise InputError(str(path), "", problem + again)
    far = np.flatnonzero(np.linalg.norm(flown - wanted, axis=1) > FILE_ROUNDING_M)
    if len(far):
        i = int(far[0])
        shown = [round(float(v), 2) for v in flown[i]]
        problem = f"{shown} (ENU), not task.work_waypoints_m[{i}] {[float(v) for v in wanted[i]]}"
        raise InputError(str(path), f"item {i + 1}", problem + again)


def check_recall_in_time(world: KnownWorld) -> None:
    """With dynamic roles, a released support can be back in the formation in time: its
    longest flight (around the structure, at its speed limit) from one of its inspection
    waypoints to its planned waypoint where the work UAV's path enters the sky's shadow is
    at most ``roles.recall_clear_s``; else InputError naming that field and the flight."""
    scenario = world.scenario
    roles = scenario.roles
    if roles.policy != "dynamic" or not scenario.task.inspections:
        return
    from mission.link.plan_files import read_vehicle_waypoints
    from mission.world.routes import route_map  # scipy: imported only where routes are flown

    work = np.asarray(scenario.task.work_waypoints_m, dtype=float)
    sigma = world.gnss.sigma0(work)
    trusted = np.isfinite(sigma) & (sigma <= roles.own_fix_max_sigma_m)
    entries = [j for j in range(len(work)) if not trusted[j] and (j == 0 or trusted[j - 1])]
    if not entries:
        return
    routes = route_map(world)
    speed = scenario.control.s_max_support_m_s
    for inspection in scenario.task.inspections:
        formation = read_vehicle_waypoints(scenario, inspection.vehicle)[entries]
        lengths = routes.lengths(np.asarray(inspection.waypoints_m, dtype=float), formation)
        i, j = np.unravel_index(int(np.argmax(lengths)), lengths.shape)
        flight_s = float(lengths[i, j]) / speed
        if flight_s > roles.recall_clear_s:
            problem = (
                f"{roles.recall_clear_s:g} s is less than {inspection.vehicle}'s flight back from "
                f"its inspection waypoint {i + 1} to the formation where the work UAV enters the "
                f"shadow (work waypoint {entries[j] + 1}): {flight_s:.1f} s at {speed:g} m/s; it "
                "could not be recalled in time"
            )
            raise InputError(scenario.source, "roles.recall_clear_s", problem)
