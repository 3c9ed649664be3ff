"""What does not move: the structure's mesh, the multipath zones (analysis may show them; the
ground station never sees them), the workspace and each vehicle's planned waypoints."""

from __future__ import annotations

import sys
from dataclasses import dataclass, field

import numpy as np

from mission.config.errors import InputError
from mission.config.settings import Scenario
from mission.link.plan_files import read_vehicle_waypoints, vehicle_names
from mission.world.model import World
from mission.world.wind import WindField


@dataclass(frozen=True)
class Scene:
    """The static part of the view, ENU metres."""

    vertices: np.ndarray  # (V, 3) of the structure's mesh
    triangles: np.ndarray  # (T, 3)
    zones: list[tuple[str, np.ndarray, np.ndarray]]  # (name, min corner, max corner)
    workspace: tuple[np.ndarray, np.ndarray]
    waypoints: dict[str, np.ndarray]  # per vehicle, (I, 3); empty where the plan is missing
    voxel_origin: np.ndarray
    voxel_m: float
    wind: np.ndarray  # the free stream (ENU, m/s); zeros in still air
    body_radius_m: float = 0.25  # a UAV drawn as its bounding body (vehicle.radius_m)
    inspections: dict[str, np.ndarray] = field(default_factory=dict)  # a support's own, (n, 3)
    # the true GNSS error field where the multipath comes from geometry: voxel indices (n, 3)
    # and |error| there (n,), the voxels above GNSS_ERROR_SHOWN_M only; None with zones
    gnss_error: tuple[np.ndarray, np.ndarray] | None = None


def build_scene(scenario: Scenario, world: World) -> Scene:
    """The scene of a scenario's world; a vehicle whose waypoint file is gone gets none (said
    on stderr), since a run's view does not need them to show what happened."""
    waypoints = {}
    for name in vehicle_names(scenario.task.supports):
        try:
            waypoints[name] = read_vehicle_waypoints(scenario, name)
        except InputError as error:
            print(f"view: no planned waypoints shown for {name}: {error}", file=sys.stderr)
            waypoints[name] = np.zeros((0, 3))
    space = scenario.world.workspace
    grid = world.map_grid()
    return Scene(
        vertices=world.structure.vertices,
        triangles=world.structure.faces,
        zones=[(z.name, np.array(z.min_m), np.array(z.max_m)) for z in scenario.world.zones],
        workspace=(np.array(space.min_m), np.array(space.max_m)),
        waypoints=waypoints,
        voxel_origin=np.array(grid.origin_m, dtype=float),
        voxel_m=float(grid.voxel_m),
        wind=WindField(scenario.world.wind, []).free_stream,
        body_radius_m=scenario.vehicle.radius_m,
        inspections={i.vehicle: np.array(i.waypoints_m) for i in scenario.task.inspections},
        gnss_error=gnss_error_voxels(world),
    )


GNSS_ERROR_SHOWN_M = 0.5  # the error field's voxels shown from this error up


def gnss_error_voxels(world: World) -> tuple[np.ndarray, np.ndarray] | None:
    """The receiver's error (no noise) at every voxel centre of G's grid, where it is at least
    GNSS_ERROR_SHOWN_M or there is no fix (shown as NaN), outside the structure; None where
    the multipath comes from zones alone."""
    if world.receiver is None:
        return None
    grid = world.map_grid()
    centers = grid.centers().reshape(-1, 3)
    solution = world.receiver.solve(centers)
    error = np.linalg.norm(solution.position_error_m, axis=1)  # NaN without a fix
    shown = ~(error < GNSS_ERROR_SHOWN_M) & ~world.structure.contains(centers)
    indices = np.argwhere(shown.reshape(grid.shape))
    return indices, error[shown]
