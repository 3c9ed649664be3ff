"""The world of a scenario, in two kinds: what anyone may know of it (:class:`KnownWorld`:
structure, sky, GNSS and camera models, workspace) and the simulated world (:class:`World`:
the known world and where GNSS errors come from: the multipath zones, reflections off the
structure, or both).

The ground station is built from a :class:`KnownWorld`, so the multipath model is out of its
reach by type, not by a promise; the vehicles and analysis take a :class:`World`.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from typing import Self

import numpy as np

from mission.config.scenario import default_signal_settings, load_scenario
from mission.config.settings import Scenario
from mission.world.camera import CameraModel
from mission.world.gnss import GnssFix, GnssModel
from mission.world.grid import VoxelGrid
from mission.world.multipath import GeometricReceiver
from mission.world.sky import load_sky
from mission.world.structure import Structure, build_structure
from mission.world.zones import MultipathZones

CLEARANCE_TOLERANCE_M = 1e-6  # a waypoint exactly at the margin is on it


@dataclass(frozen=True)
class Sigma0Map:
    """sigma_0 = sqrt(tr Sigma_GNSS) at every voxel centre, capped where there is no fix."""

    grid: VoxelGrid
    sigma_m: np.ndarray
    has_fix: np.ndarray
    n_visible: np.ndarray
    build_s: float


class KnownWorld:
    """What anyone may know of a scenario: the structure, the sky, the GNSS and camera models
    and the workspace, and nothing of the multipath zones: its scenario has none. This is the
    world the ground station gets."""

    def __init__(self, scenario: Scenario, structure: Structure | None = None) -> None:
        """Build it for ``scenario`` (whose zones are left out); ``structure``: the scenario's
        structure if already built."""
        self.scenario = without_multipath(scenario)
        if structure is None:
            structure = build_structure(scenario.world.structure, scenario.source)
        self.structure = structure
        self.sky = load_sky(scenario.sky)
        self.gnss = GnssModel(self.sky, self.structure, scenario.gnss)
        self.camera = CameraModel(scenario.camera, self.structure)
        self.workspace = scenario.world.workspace

    @classmethod
    def load(cls, name_or_path: str) -> Self:
        """Load a scenario by name or path and build its world."""
        return cls(load_scenario(name_or_path))

    def in_workspace(self, points: np.ndarray) -> np.ndarray:
        """True for points inside the workspace box."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        lo, hi = self.workspace.min_m, self.workspace.max_m
        if len(points) == 1:  # a setpoint: plain floats, the same comparisons
            point = points[0].tolist()
            return np.array([all(a <= x <= b for a, x, b in zip(lo, point, hi, strict=True))])
        return np.all((points >= np.array(lo)) & (points <= np.array(hi)), axis=1)

    def placement_problem(self, point: np.ndarray) -> str | None:
        """Why a vehicle cannot be at ``point`` ("outside the workspace", "inside the
        structure"), or None where it can."""
        point = np.asarray(point, dtype=float)[None]
        if not self.in_workspace(point)[0]:
            return "outside the workspace"
        if self.structure.contains(point)[0]:
            return "inside the structure"
        return None

    def clearance_problem(self, point: np.ndarray) -> str | None:
        """Why a scenario's waypoint is too close to the structure to be flown to: within
        ``control.clearance_m``, the margin the MPCs keep from it (None: it is not)."""
        from mission.world.proximity import StructureProximity

        margin = self.scenario.control.clearance_m
        distance = float(StructureProximity(self.structure).distance(point)[0])
        if distance < margin - CLEARANCE_TOLERANCE_M:
            return (
                f"{distance:.2f} m from the structure, closer than control.clearance_m "
                f"({margin:g} m), the margin the MPCs keep: it could never be reached"
            )
        return None

    def map_grid(self) -> VoxelGrid:
        """The voxel grid of the GNSS-localizability map."""
        return VoxelGrid.over(self.workspace, self.scenario.map.voxel_size_m)

    def sigma0_map(self) -> Sigma0Map:
        """sigma_0 over the whole map grid (what G starts from), no-fix voxels capped."""
        start = time.perf_counter()
        grid = self.map_grid()
        centers = grid.centers().reshape(-1, 3)
        geometry = self.gnss.geometry(centers)
        sigma = self.scenario.gnss.sigma_uere_m * geometry.pdop
        cap = self.scenario.map.no_fix_sigma_m
        sigma = np.where(geometry.has_fix, np.minimum(sigma, cap), cap)
        return Sigma0Map(
            grid=grid,
            sigma_m=sigma.reshape(grid.shape),
            has_fix=geometry.has_fix.reshape(grid.shape),
            n_visible=geometry.n_visible.reshape(grid.shape),
            build_s=time.perf_counter() - start,
        )


class World(KnownWorld):
    """The simulated world: the known world and what biases GNSS fixes (``world.gnss``): the
    multipath zones, the reflections off the structure and the ground, or both. For the
    vehicles and for analysis; never for the ground station."""

    def __init__(self, scenario: Scenario) -> None:
        super().__init__(scenario)
        self.scenario = scenario
        self.zones = MultipathZones(scenario.world.zones)
        signal = scenario.world.gnss
        self.receiver = (
            GeometricReceiver(self.gnss, signal, scenario.source) if signal.uses_geometry else None
        )

    def gnss_fix(
        self,
        truth: np.ndarray,
        rng: np.random.Generator,
        sigma_uere_m: float | None = None,
        multipath_scale: float = 1.0,
    ) -> GnssFix:
        """A receiver's fix at ``truth``: noise of ``sigma_uere_m`` and the multipath of the
        scenario's model times ``multipath_scale`` (a vehicle's SIM_MP_SCALE)."""
        offset = self.zone_offset(truth[None])[0]
        if multipath_scale != 1.0:
            offset = multipath_scale * offset
        if self.receiver is None:
            return self.gnss.sample_fix(truth, rng, offset, sigma_uere_m=sigma_uere_m)
        return self.receiver.sample_fix(truth, rng, offset, sigma_uere_m, multipath_scale)

    def known(self) -> KnownWorld:
        """This world without its multipath model (the same structure)."""
        return KnownWorld(self.scenario, self.structure)

    def in_zone(self, points: np.ndarray) -> np.ndarray:
        """True for points inside a multipath zone."""
        return self.zones.contains(points)

    def zone_offset(self, points: np.ndarray) -> np.ndarray:
        """g_offset at each point: the containing zone's offset, zero elsewhere."""
        return self.zones.offset(points)


def without_multipath(scenario: Scenario) -> Scenario:
    """The scenario with no multipath model: no zones, and ``world.gnss`` as the defaults
    have it (zones, of which there are none; the default surfaces and receiver), whatever
    the scenario's own; everything else the same."""
    world = scenario.world
    gnss = default_signal_settings()
    if not world.zones and world.gnss == gnss:
        return scenario
    return dataclasses.replace(scenario, world=dataclasses.replace(world, zones=[], gnss=gnss))
