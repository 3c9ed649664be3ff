"""What the control cycle computes with, built once per run from the known world."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ground_station.estimation.gnss_map import LocalizabilityMap
from ground_station.integrity.monitor import IntegrityMonitor
from ground_station.state.station_state import StationState
from ground_station.support_mpc.mpc import SupportMpc
from ground_station.support_mpc.sharing import HelperPlanner, LocalPlanner, MpcHelper
from mission.config.settings import Scenario
from mission.world.model import KnownWorld, World
from mission.world.routes import RouteMap, route_map


@dataclass
class RunContext:
    """The scenario and the known world, the planned waypoints, the map G, the support MPC,
    the fusion's random generator, who solves the support MPCs, and, where the supports have
    inspections of their own, those waypoints and the routes to fly them."""

    scenario: Scenario
    world: KnownWorld
    work_waypoints: np.ndarray
    support_waypoints: dict[str, np.ndarray]
    g: LocalizabilityMap
    support_mpc: SupportMpc
    rng: np.random.Generator
    planner: LocalPlanner  # solves the support MPCs: here, or shared with a helper process
    inspections: dict[str, np.ndarray] = field(default_factory=dict)  # support -> (n, 3)
    routes: RouteMap | None = None  # None without inspections
    integrity: IntegrityMonitor | None = None  # None where the monitor is off


def build_run_context(
    world: KnownWorld,
    waypoints: dict[str, np.ndarray],
    adaptive: bool,
    seed: int,
    helper: MpcHelper | None = None,
    sigma0: np.ndarray | None = None,
) -> tuple[RunContext, StationState]:
    """Everything the control cycle needs, and the state at the start (vehicles at w_1); the
    support MPCs are shared with ``helper`` if one is given. ``sigma0`` is the world's sigma_0
    map if already computed."""
    scn = require_known_world(world).scenario
    grid = world.map_grid()
    if sigma0 is None:
        sigma0 = world.sigma0_map().sigma_m
    g = LocalizabilityMap(grid, sigma0, scn.map, adaptive)
    supports = {n: w for n, w in waypoints.items() if n != "work"}
    mpc = SupportMpc(scn.control, grid, world.camera, g.initial, others=scn.task.supports)
    observable = world.camera.observable
    planner = (
        LocalPlanner(mpc, observable) if helper is None else HelperPlanner(mpc, observable, helper)
    )
    inspections = {i.vehicle: np.array(i.waypoints_m, dtype=float) for i in scn.task.inspections}
    context = RunContext(
        scn,
        world,
        waypoints["work"],
        supports,
        g,
        mpc,
        np.random.default_rng(seed),
        planner,
        inspections,
        route_map(world, sigma0) if inspections else None,
        _monitor(world),
    )
    state = StationState(
        xhat=waypoints["work"][0].copy(),
        yhat={n: w[0].copy() for n, w in supports.items()},
        k=min(1, len(waypoints["work"]) - 1),
    )
    return context, state


def _monitor(world: KnownWorld) -> IntegrityMonitor | None:
    """The integrity monitor where the scenario has it on."""
    scenario = world.scenario
    if not scenario.integrity.enabled:
        return None
    multicopter = scenario.vehicle.dynamics == "multicopter"
    voxel_m = scenario.map.voxel_size_m
    return IntegrityMonitor(scenario.integrity, multicopter, voxel_m, world.camera.covariance)


def require_known_world(world: KnownWorld) -> KnownWorld:
    """``world``, if it is a known world; a simulated :class:`World`, which has the multipath
    zones, is refused (TypeError): give the ground station ``world.known()``."""
    if isinstance(world, World) or not isinstance(world, KnownWorld):
        raise TypeError(f"the ground station takes a KnownWorld, not a {type(world).__name__}")
    return world
