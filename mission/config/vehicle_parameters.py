"""The catalogue of a simulated vehicle's parameters: ids, types, ranges, and which can change
during a run.

Ids follow ArduPilot where it has the same setting (``WPNAV_SPEED``, ``FS_GCS_TIMEOUT``,
``SR0_*``, ``SIM_GPS1_*``, ``SIM_WIND_SPD``, ``SIM_WIND_DIR``), PX4 for a multicopter's
position controller (``MPC_*``, as PX4's ``mc_pos_control`` names them; the ranges are the
ones our loops accept), our own ``SIM_*`` where neither has one (ArduPilot's
``SIM_WIND_TURB`` is an amplitude in m/s; ours, ``SIM_WIND_DRYDEN``, scales MIL-F-8785C's
intensities). The vehicle builds its table from this catalogue and the scenario
(``vehicle_sim.mavlink.parameters``); a scenario's ``faults:`` are checked against it before
any process starts. docs/vehicle.md lists every entry.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

ID_LENGTH = 16  # param_id: 16 characters, not terminated when all are used
FIXED_FOR_THE_RUN = "fixed for the run: set it in the scenario"
_STREAM = "a stream's rate: SET_MESSAGE_INTERVAL"
_CLOCK = "the run's clock: --speedup"


@dataclass(frozen=True)
class ParameterSpec:
    """One parameter: its id, whether it holds whole numbers, the range a value must fall in,
    and why it cannot be set during a run (None: it can, and the vehicle applies it before
    its next step)."""

    name: str
    integer: bool
    low: float
    high: float
    meaning: str
    read_only: str | None = None

    def __post_init__(self) -> None:
        if not 0 < len(self.name) <= ID_LENGTH or not self.name.isascii():
            raise ValueError(f"parameter id {self.name!r}: 1-{ID_LENGTH} ASCII characters")

    def refusal(self, value: float) -> str | None:
        """Why ``value`` cannot be set (None: it can)."""
        if self.read_only is not None:
            return self.read_only
        if not math.isfinite(value):
            return "needs a finite value"
        if self.integer and value != round(value):
            return "needs a whole number"
        if not self.low <= value <= self.high:
            return f"must be in [{self.low:g}, {self.high:g}]"
        return None


def _live(name: str, integer: bool, low: float, high: float, meaning: str) -> ParameterSpec:
    return ParameterSpec(name, integer, low, high, meaning)


def _fixed(name: str, integer: bool, meaning: str, why: str = FIXED_FOR_THE_RUN) -> ParameterSpec:
    return ParameterSpec(name, integer, -math.inf, math.inf, meaning, why)


PARAMETERS: tuple[ParameterSpec, ...] = (
    # the vehicle's own, under ArduPilot's names
    _live("FS_GCS_TIMEOUT", False, 0.1, 120, "s without a setpoint before the failsafe holds"),
    _live("WPNAV_SPEED", False, 10, 5000, "the speed limit, cm/s (control.s_max_*)"),
    _fixed("SR0_EXTRA1", True, "sensor message rate, Hz", _STREAM),
    _fixed("SR0_EXT_STAT", True, "status message rate, Hz", _STREAM),
    # the simulation's, under ArduPilot's names where the meaning is the same
    _fixed("SIM_RATE_HZ", True, "simulation steps per second (1 / control.t_cont_s)"),
    _fixed("SIM_SPEEDUP", False, "the run's speed-up (1 in lockstep)", _CLOCK),
    _live("SIM_GPS1_ENABLE", True, 0, 1, "the GNSS receiver on (1) or off (0)"),
    _live("SIM_GPS1_HZ", True, 1, 100, "the GNSS receiver's rate, Hz (at most one fix a step)"),
    _live("SIM_GPS1_LAG_MS", True, 0, 1000, "the GNSS fix's lag, ms (whole steps)"),
    _live("SIM_GPS1_GLTCH_X", False, -1, 1, "a glitch added to the fix's latitude, degrees"),
    _live("SIM_GPS1_GLTCH_Y", False, -1, 1, "a glitch added to the fix's longitude, degrees"),
    _live("SIM_GPS1_GLTCH_Z", False, -1000, 1000, "a glitch added to the fix's altitude, m"),
    # ours, for what ArduPilot lacks
    _live("SIM_GPS_UERE", False, 0, 100, "the GNSS sigma_UERE, m (gnss.sigma_uere_m)"),
    _live("SIM_MP_SCALE", False, 0, 10, "scale of the multipath zones' bias (1: the world's)"),
    _live("SIM_CAM_RANGE", False, 0, 1000, "the camera's range, m (camera.range_m)"),
    _live("SIM_CAM_NOISE", False, 0, 100, "scale of the camera's noise (1: camera.sigma_*)"),
    _live("SIM_TRACK_NOISE", False, 0, 10, "tracking noise per step, m (vehicle.tracking_noise_m)"),
    _live("SIM_WIND_SPD", False, 0, 40, "the mean wind, m/s (world.wind.speed_m_s; multicopters)"),
    _live(
        "SIM_WIND_DIR", False, 0, 360, "where the wind blows from, degrees (world.wind.from_deg)"
    ),
    _live("SIM_WIND_DRYDEN", False, 0, 10, "scale of the Dryden gusts (world.wind.turbulence)"),
    _live("SIM_LINK_LOSS", False, 0, 0.9, "chance a datagram sent is lost (--link-loss)"),
    _fixed("SIM_RADIUS", False, "the body's radius for contact, m (vehicle.radius_m)"),
    _live("SIM_FAIL_ENABLE", True, 0, 1, "1 allows MAV_CMD_INJECT_FAILURE (PX4's SYS_FAILURE_EN)"),
    # a multicopter's position controller, under PX4's names (vehicle.autopilot.*)
    _live("MPC_XY_P", False, 0.1, 2, "horizontal position gain, 1/s (multicopters)"),
    _live("MPC_Z_P", False, 0.1, 1.5, "vertical position gain, 1/s (multicopters)"),
    _live("MPC_XY_VEL_P_ACC", False, 1.2, 5, "horizontal velocity P, 1/s (multicopters)"),
    _live("MPC_XY_VEL_I_ACC", False, 0, 3, "horizontal velocity I, 1/s2 (multicopters)"),
    _live("MPC_XY_VEL_D_ACC", False, 0, 2, "horizontal velocity D (multicopters)"),
    _live("MPC_Z_VEL_P_ACC", False, 2, 15, "vertical velocity P, 1/s (multicopters)"),
    _live("MPC_Z_VEL_I_ACC", False, 0.2, 3, "vertical velocity I, 1/s2 (multicopters)"),
    _live("MPC_XY_VEL_MAX", False, 0.5, 20, "horizontal speed limit, m/s (multicopters)"),
    _live("MPC_Z_VEL_MAX_UP", False, 0.5, 8, "climb speed limit, m/s (multicopters)"),
    _live("MPC_Z_VEL_MAX_DN", False, 0.5, 4, "descent speed limit, m/s (multicopters)"),
    _live("MPC_TILTMAX_AIR", False, 20, 89, "tilt limit, degrees (multicopters)"),
    _live("MPC_THR_MIN", False, 0.05, 0.5, "least collective thrust, of the most (multicopters)"),
    _live("MPC_THR_XY_MARG", False, 0, 0.5, "horizontal thrust margin, of the most (multicopters)"),
)
_BY_NAME = {spec.name: spec for spec in PARAMETERS}


def parameter_spec(name: str) -> ParameterSpec | None:
    """The catalogue's entry for ``name`` (None: no such parameter)."""
    return _BY_NAME.get(name)


def live_parameter_names() -> list[str]:
    """The ids that can be set during a run, sorted."""
    return sorted(spec.name for spec in PARAMETERS if spec.read_only is None)
