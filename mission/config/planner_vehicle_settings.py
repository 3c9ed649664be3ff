"""Settings of the offline planner and of a simulated vehicle."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from mission.config.autopilot_settings import AutopilotSettings
from mission.config.checks import as_parameter as _as_parameter
from mission.config.checks import at_most as _at_most
from mission.config.checks import non_negative as _non_negative
from mission.config.checks import positive as _positive
from mission.config.checks import require as _require
from mission.config.flight_checks import check_flyable
from mission.config.multicopter_settings import MulticopterSettings


@dataclass(frozen=True)
class PlannerSettings:
    """The offline planner of the support UAVs' paths (docs/model.md, "Pre-planned support
    paths"; the paper's ref. [18])."""

    lattice_m: float
    w_gnss_per_m2: float
    w_relative_per_m2: float
    w_move_per_m: float
    w_spread: float
    min_separation_m: float
    clearance_m: float
    min_altitude_m: float
    max_range_fraction: float
    rounds: int

    def __post_init__(self) -> None:
        _positive(self, "lattice_m", "max_range_fraction")
        _non_negative(self, "w_gnss_per_m2", "w_relative_per_m2", "w_move_per_m", "w_spread")
        _non_negative(self, "min_separation_m", "clearance_m", "min_altitude_m")
        _require(self.max_range_fraction <= 1, "max_range_fraction", "must be at most 1")
        _require(self.rounds >= 1, "rounds", "must be at least 1")


KINEMATIC_RADIUS_M = 0.25  # a kinematic vehicle's sphere (frame and propellers)
MIN_HEARTBEAT_HZ = 0.2
MAX_STREAM_HZ = 100.0


@dataclass(frozen=True)
class VehicleSettings:
    """A simulated vehicle: realism, failsafe, telemetry rates and protocol timing.

    Rates are in simulated time; the ``*_wall_s`` timeouts are wall-clock seconds, divided by
    the speed-up in real-time mode.
    """

    tracking_noise_m: float
    radius_m: float | None  # None: the default for the dynamics (:func:`body_radius`), a
    # number once built (``dataclasses.replace`` of the dynamics keeps that number: load the
    # scenario with the override to get the other default)
    failsafe_s: float
    heartbeat_hz: float
    status_hz: float
    sensor_hz: float
    lockstep_timeout_wall_s: float
    truth_timeout_wall_s: float
    mission_timeout_wall_s: float
    mission_retries: int
    mission_capacity: int
    dynamics: Literal["kinematic", "multicopter"]
    multicopter: MulticopterSettings
    autopilot: AutopilotSettings

    def __post_init__(self) -> None:
        if self.radius_m is None:  # frozen: set once, as the scenario leaves it to the default
            object.__setattr__(self, "radius_m", body_radius(self))
        _non_negative(self, "tracking_noise_m")
        _positive(self, "radius_m")
        _positive(self, "failsafe_s", "heartbeat_hz", "status_hz", "sensor_hz")
        _positive(self, "lockstep_timeout_wall_s", "truth_timeout_wall_s", "mission_timeout_wall_s")
        _require(self.mission_retries >= 0, "mission_retries", "must not be negative")
        _as_parameter("tracking_noise_m", self.tracking_noise_m, "SIM_TRACK_NOISE")
        _as_parameter("failsafe_s", self.failsafe_s, "FS_GCS_TIMEOUT")
        _as_parameter("sensor_hz", round(self.sensor_hz), "SIM_GPS1_HZ", " (rounded)")
        _require(
            self.heartbeat_hz >= MIN_HEARTBEAT_HZ,
            "heartbeat_hz",
            f"must be at least {MIN_HEARTBEAT_HZ:g} Hz (a ground station takes 5 s without "
            "one for a lost link)",
        )
        _require(
            round(self.status_hz) >= 1, "status_hz", "must round to at least 1 Hz (SR0_EXT_STAT)"
        )
        _at_most(self, MAX_STREAM_HZ, "a message every 10 ms", "heartbeat_hz", "status_hz")
        for name, least in (("lockstep_timeout_wall_s", 0.1), ("mission_timeout_wall_s", 0.05)):
            _require(
                getattr(self, name) >= least,
                name,
                f"must be at least {least:g} s of wall time (a loaded machine's scheduling "
                "alone takes that long)",
            )
        _require(self.mission_capacity >= 1, "mission_capacity", "must be at least 1")
        if self.dynamics == "multicopter":
            check_flyable(self.multicopter, self.autopilot)


def body_radius(vehicle: VehicleSettings) -> float:
    """The bounding radius a scenario leaves to the default: a multicopter's rotor tips, a
    kinematic vehicle's :data:`KINEMATIC_RADIUS_M`."""
    if vehicle.dynamics == "multicopter":
        return vehicle.multicopter.rotor_tips_m
    return KINEMATIC_RADIUS_M
