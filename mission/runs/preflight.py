"""Everything a run reads from files, checked before any of its processes starts."""

from __future__ import annotations

from pathlib import Path


def preflight(scenario) -> None:
    """Everything a run reads from files, checked before any process starts: the structure's
    mesh (loading the known world; every triangle with a normal where it reflects signals),
    every vehicle's waypoint file (the work UAV's the scenario's path), the supports' own
    inspection waypoints against the structure, and, with dynamic roles, that a released
    support can be recalled in time."""
    from mission.link.plan_check import (
        check_inspections_placed,
        check_plan_files,
        check_recall_in_time,
        check_work_plan_matches,
        check_work_waypoints_clear,
    )
    from mission.link.plan_files import vehicle_names
    from mission.world.model import KnownWorld

    world = KnownWorld(scenario)
    if scenario.world.gnss.uses_geometry:
        from mission.world.reflections import check_reflecting_faces

        check_reflecting_faces(world.structure, scenario.source)
    check_work_waypoints_clear(world)
    names = vehicle_names(scenario.task.supports)
    check_plan_files(world, Path(scenario.task.waypoints_dir), names)
    check_work_plan_matches(world, Path(scenario.task.waypoints_dir))
    check_inspections_placed(world)
    check_recall_in_time(world)
