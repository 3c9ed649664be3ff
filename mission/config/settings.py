"""Scenario settings: frozen dataclasses, one per concern, each validating itself.

Every number has its default in ``mission/scenarios/defaults.yaml`` (the single source of
defaults); field names carry their units (``_m``, ``_s``, ``_deg``, ``_hz``, ``_m_s``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from datetime import datetime
from typing import Literal

from mission.config.checks import as_parameter as _as_parameter
from mission.config.checks import at_most as _at_most
from mission.config.checks import non_negative as _non_negative
from mission.config.checks import positive as _positive
from mission.config.checks import require as _require
from mission.config.errors import FieldProblem
from mission.config.fault_settings import Fault, check_faults
from mission.config.flight_checks import check_fault_tunings
from mission.config.integrity_settings import IntegritySettings
from mission.config.limit_settings import LimitSettings
from mission.config.planner_vehicle_settings import PlannerSettings, VehicleSettings
from mission.config.role_settings import (
    Inspection,
    RoleSettings,
    check_roles,
    check_waypoints,
)
from mission.config.sensor_settings import CameraSettings, GnssSettings, SkySettings
from mission.config.signal_settings import SignalSettings
from mission.config.wind_settings import WindSettings

Vec3 = tuple[float, float, float]
MAX_COORDINATE_M = 100_000.0  # a world-frame coordinate beyond this is not a site's metres


@dataclass(frozen=True)
class Box:
    """Axis-aligned box in the world frame (ENU, metres)."""

    min_m: Vec3
    max_m: Vec3

    def __post_init__(self) -> None:
        for corner, name in ((self.min_m, "min_m"), (self.max_m, "max_m")):
            _require(
                all(abs(v) <= MAX_COORDINATE_M for v in corner),
                name,
                f"coordinates are metres from the anchor, at most {MAX_COORDINATE_M:g}: {corner}",
            )
        for axis in range(3):
            _require(
                self.min_m[axis] < self.max_m[axis],
                "max_m",
                f"must exceed min_m on every axis (axis {'xyz'[axis]}: "
                f"{self.min_m[axis]} >= {self.max_m[axis]})",
            )

    def contains_box(self, other: Box) -> bool:
        """True when ``other`` lies inside this box (faces may touch)."""
        return all(
            self.min_m[a] <= other.min_m[a] and other.max_m[a] <= self.max_m[a] for a in range(3)
        )

    @property
    def size_m(self) -> Vec3:
        """Edge lengths along x, y, z."""
        return tuple(hi - lo for lo, hi in zip(self.min_m, self.max_m))  # type: ignore[return-value]


@dataclass(frozen=True)
class GeodeticAnchor:
    """Geodetic origin of the local ENU world frame (WGS-84)."""

    lat_deg: float
    lon_deg: float
    alt_m: float

    def __post_init__(self) -> None:
        _require(-90 <= self.lat_deg <= 90, "lat_deg", f"must be in [-90, 90], got {self.lat_deg}")
        _require(
            -180 <= self.lon_deg <= 180, "lon_deg", f"must be in [-180, 180], got {self.lon_deg}"
        )


@dataclass(frozen=True)
class BoxPrimitive:
    """A solid box of the structure (deck, pier, ...)."""

    name: str
    min_m: Vec3
    max_m: Vec3

    def __post_init__(self) -> None:
        Box(self.min_m, self.max_m)


@dataclass(frozen=True)
class StructureSettings:
    """The structure: primitives and/or a mesh file (STL/OBJ/PLY, metres, world frame).

    Both are used when both are given; set ``primitives: []`` to use the mesh file alone.
    """

    mesh_file: str | None
    primitives: list[BoxPrimitive]

    def __post_init__(self) -> None:
        _require(
            bool(self.primitives) or self.mesh_file is not None,
            "primitives",
            "the structure needs at least one primitive or a mesh_file",
        )


MAX_ZONE_OFFSET_M = 1000.0


@dataclass(frozen=True)
class Zone:
    """A multipath-affected space: GNSS fixes inside it are offset by ``offset_m``."""

    name: str
    min_m: Vec3
    max_m: Vec3
    offset_m: Vec3

    def __post_init__(self) -> None:
        Box(self.min_m, self.max_m)
        _require(
            all(math.isfinite(v) and abs(v) <= MAX_ZONE_OFFSET_M for v in self.offset_m),
            "offset_m",
            f"each component must be at most {MAX_ZONE_OFFSET_M:g} m (NLOS errors stay within "
            "hundreds of metres; a fix beyond is no longer near the Earth)",
        )

    @property
    def box(self) -> Box:
        """The zone's extent as a box."""
        return Box(self.min_m, self.max_m)


@dataclass(frozen=True)
class WorldSettings:
    """Structure, workspace and multipath zones (zones are known to the vehicles only)."""

    anchor: GeodeticAnchor
    workspace: Box
    structure: StructureSettings
    zones: list[Zone]
    wind: WindSettings
    gnss: SignalSettings  # where the fixes' errors come from (zones, geometry or both)

    def __post_init__(self) -> None:
        extent = min(b - a for a, b in zip(self.workspace.min_m, self.workspace.max_m))
        _require(
            self.wind.edge_width_m < extent / 2,
            "wind.edge_width_m",
            f"{self.wind.edge_width_m:g} m does not fit the workspace (its smallest extent is "
            f"{extent:g} m)",
        )
        for i, zone in enumerate(self.zones):
            _require(
                self.workspace.contains_box(zone.box),
                f"zones[{i}]",
                f"zone '{zone.name}' {zone.min_m}..{zone.max_m} lies outside the workspace "
                f"{self.workspace.min_m}..{self.workspace.max_m}",
            )
        names = [z.name for z in self.zones]
        for i, name in enumerate(names):
            _require(names.index(name) == i, f"zones[{i}].name", f"duplicate zone name '{name}'")
        _require(
            self.gnss.uses_zones or not self.zones,
            "gnss.multipath",
            "'geometry' leaves the scenario's zones without effect: use 'both', or set zones: []",
        )


@dataclass(frozen=True)
class FusionSettings:
    """Selective fusion (paper 3.2.1) with the candidate-particle sets of docs/model.md,
    "Selective fusion"."""

    broad_particles: int
    local_particles: int
    broad_sigma_m: float
    rho_threshold: float
    agreement: Literal["contributing", "paper"]  # S: agreeing with half of these, or of N

    def __post_init__(self) -> None:
        _require(self.broad_particles >= 2, "broad_particles", "must be at least 2")
        _non_negative(self, "local_particles")
        _positive(self, "broad_sigma_m")
        _require(
            -1 <= self.rho_threshold <= 1,
            "rho_threshold",
            f"must be in [-1, 1], got {self.rho_threshold}",
        )


@dataclass(frozen=True)
class MapSettings:
    """GNSS-localizability map G (paper 4.1)."""

    voxel_size_m: float
    eta: float
    neighborhood: float
    no_fix_sigma_m: float

    def __post_init__(self) -> None:
        _positive(self, "voxel_size_m", "no_fix_sigma_m")
        _require(0 <= self.eta <= 1, "eta", f"must be in [0, 1], got {self.eta}")
        _non_negative(self, "neighborhood")


MAX_WEIGHT = 1e6
# a flying quadrotor's tracking error with the velocity feed-forward, p95 over a run's cycles
# (docs/model.md, "A ground station that knows the lag"); a kinematic point tracks exactly
FLYING_TRACKING_ALLOWANCE_M = 0.3


def tracking_allowance(dynamics: str) -> float:
    """The default tracking allowance for vehicles of ``dynamics``."""
    return FLYING_TRACKING_ALLOWANCE_M if dynamics == "multicopter" else 0.0


MAX_T_PRED_S = 10.0


@dataclass(frozen=True)
class ControlSettings:
    """MPC and control-cycle parameters (paper 4.2, Table 2 as docs/model.md, "MPCs", fills it)."""

    horizon_steps: int
    t_pred_s: float
    t_cont_s: float
    s_max_work_m_s: float
    s_max_support_m_s: float
    w_gnss: float
    w_interval: float
    w_waypoint: float
    w_relative: float
    w_penalty: float
    arrival_tol_m: float
    support_max_sigma0_m: float
    los_penalty: Literal["visible-point", "paper"]
    mpc_solver: Literal["fatrop", "ipopt"]
    escape_starts: bool  # where G has risen, also start the support MPC from escaping paths
    min_separation_m: float  # between any two UAVs over the MPCs' horizon (0: no margin)
    clearance_m: float  # from the structure and the ground over the horizon (0: no margin)
    estimate_allowance_m: float  # the MPCs keep margins this much wider per estimate involved
    tracking_allowance_m: float | None  # ... and this much per vehicle for its tracking error
    # (None in a scenario: the default for the vehicles' dynamics, set by the Scenario once;
    # ``dataclasses.replace`` of the dynamics keeps it)
    velocity_feedforward: bool  # flying vehicles get the plan's velocity with its position

    def __post_init__(self) -> None:
        _require(self.horizon_steps >= 1, "horizon_steps", "must be at least 1")
        _non_negative(self, "min_separation_m", "clearance_m", "estimate_allowance_m")
        if self.tracking_allowance_m is not None:
            _non_negative(self, "tracking_allowance_m")
        _positive(self, "t_pred_s", "t_cont_s", "s_max_work_m_s", "s_max_support_m_s")
        _positive(self, "arrival_tol_m", "support_max_sigma0_m")
        _non_negative(self, "w_gnss", "w_interval", "w_waypoint", "w_relative", "w_penalty")
        weights = ("w_gnss", "w_interval", "w_waypoint", "w_relative", "w_penalty")
        _at_most(self, MAX_WEIGHT, "beyond, the MPC's cost is ill-conditioned", *weights)
        _at_most(self, MAX_T_PRED_S, "a prediction step of at most 10 s", "t_pred_s")
        for name in ("s_max_work_m_s", "s_max_support_m_s"):
            _as_parameter(name, 100 * getattr(self, name), "WPNAV_SPEED", " cm/s")

    @property
    def allowance_m(self) -> float:
        """How much wider the margins are kept per vehicle involved: its estimate's error and
        its tracking error."""
        return self.estimate_allowance_m + (self.tracking_allowance_m or 0.0)

    @property
    def d_max_work_m(self) -> float:
        """Largest work-UAV step per prediction step."""
        return self.s_max_work_m_s * self.t_pred_s

    @property
    def d_max_support_m(self) -> float:
        """Largest support-UAV step per prediction step."""
        return self.s_max_support_m_s * self.t_pred_s


@dataclass(frozen=True)
class RunSettings:
    """How a run goes: its time limit, the simulated epoch of t = 0, and whether a crash
    ends it."""

    timeout_s: float
    epoch_utc: str
    stop_on_crash: bool  # a contact ends the run as failed (false: recorded, flies on)

    def __post_init__(self) -> None:
        _positive(self, "timeout_s")
        _require(math.isfinite(self.timeout_s), "timeout_s", "must be finite")
        try:
            datetime.fromisoformat(self.epoch_utc.replace("Z", "+00:00"))
        except ValueError:
            raise FieldProblem("epoch_utc", f"not an ISO-8601 time: {self.epoch_utc!r}") from None

    @property
    def epoch_unix_s(self) -> float:
        """The epoch as seconds since 1970 (UTC)."""
        return datetime.fromisoformat(self.epoch_utc.replace("Z", "+00:00")).timestamp()


@dataclass(frozen=True)
class TaskSettings:
    """The task: the work UAV's inspection waypoints and the support UAVs accompanying it.

    ``waypoints_dir`` holds the planned QGC WPL 110 files (``work.waypoints``,
    ``support-N.waypoints``), relative to the scenario file that names it.
    """

    supports: int
    work_waypoints_m: list[Vec3]
    waypoints_dir: str
    inspections: list[Inspection]  # each support's own, for when it is free

    def __post_init__(self) -> None:
        _require(1 <= self.supports <= 50, "supports", f"must be in 1..50, got {self.supports}")
        _require(len(self.work_waypoints_m) >= 2, "work_waypoints_m", "needs at least 2 points")


@dataclass(frozen=True)
class Scenario:
    """A complete scenario: everything a run needs to know, validated."""

    name: str
    description: str
    source: str
    world: WorldSettings
    sky: SkySettings
    gnss: GnssSettings
    camera: CameraSettings
    fusion: FusionSettings
    map: MapSettings
    control: ControlSettings
    run: RunSettings
    task: TaskSettings
    planner: PlannerSettings
    vehicle: VehicleSettings
    limits: LimitSettings
    faults: list[Fault]
    roles: RoleSettings
    integrity: IntegritySettings

    def __post_init__(self) -> None:
        if self.control.tracking_allowance_m is None:  # frozen: set once, as left to the default
            allowance = tracking_allowance(self.vehicle.dynamics)
            object.__setattr__(
                self, "control", replace(self.control, tracking_allowance_m=allowance)
            )
        self._check_margins()
        self._check_integrity()
        check_fault_tunings(self.faults, self.vehicle)
        check_faults(self.faults, self.task.supports, self.run.timeout_s, self.control.t_cont_s)
        check_waypoints(self.task, self.world.workspace, self.control.clearance_m)
        check_roles(self.roles, self.task.supports, self.control.arrival_tol_m)

    def _check_integrity(self) -> None:
        """The monitor's sustain and recovery fit in the run."""
        cycles = self.run.timeout_s / self.control.t_cont_s
        for name in ("sustain_cycles", "recovery_cycles"):
            value = getattr(self.integrity, name)
            _require(
                value <= cycles,
                f"integrity.{name}",
                f"{value} cycles is longer than the run ({cycles:g} cycles of "
                f"{self.control.t_cont_s:g} s in run.timeout_s {self.run.timeout_s:g} s)",
            )

    def _check_margins(self) -> None:
        """A margin, where there is one, leaves room for the bodies it keeps apart."""
        radius = self.vehicle.radius_m
        separation, clearance = self.control.min_separation_m, self.control.clearance_m
        _require(
            separation == 0 or separation >= 2 * radius,
            "control.min_separation_m",
            f"{separation:g} m is less than two bodies' radii (2 x vehicle.radius_m = "
            f"{2 * radius:g} m); 0 turns the margin off",
        )
        _require(
            clearance == 0 or clearance >= radius,
            "control.clearance_m",
            f"{clearance:g} m is less than a body's radius (vehicle.radius_m = {radius:g} m); "
            "0 turns the margin off",
        )
