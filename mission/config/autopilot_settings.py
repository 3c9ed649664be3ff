"""The autopilot of a simulated multicopter: PX4's multicopter position controller
(``src/modules/mc_pos_control``), its attitude and rate loops, and the navigation filter's
drift between estimates (docs/model.md, "A multicopter's dynamics").

The position and velocity loops' settings carry PX4's names and defaults
(``mc_pos_control_*_params.c``): each field says its PX4 parameter, and the vehicle serves them
under those ids, settable in flight as PX4's are (:data:`PX4_PARAMETERS`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from mission.config.checks import as_parameter as _as_parameter
from mission.config.checks import at_most as _at_most
from mission.config.checks import non_negative as _non_negative
from mission.config.checks import positive as _positive
from mission.config.checks import require as _require

MIN_TILT_DEG = 20.0  # MPC_TILTMAX_AIR's range here
MAX_TILT_DEG = 89.0  # PX4 caps MPC_TILTMAX_AIR there


@dataclass(frozen=True)
class AutopilotSettings:
    """The position controller's cascade, as PX4 runs it: position error -> velocity setpoint
    (horizontal speed capped by norm, climb and descent separately) -> acceleration (PID, the
    integral with anti-windup) -> thrust vector (tilt, then thrust limited with vertical
    priority) -> attitude -> body rates -> the mixer's rotor commands (desaturated)."""

    position_gain_per_s: float  # MPC_XY_P
    vertical_position_gain_per_s: float  # MPC_Z_P
    velocity_gain_per_s: float  # MPC_XY_VEL_P_ACC
    velocity_integral_gain_per_s2: float  # MPC_XY_VEL_I_ACC
    velocity_derivative_gain: float  # MPC_XY_VEL_D_ACC, on the filtered acceleration
    velocity_derivative_cutoff_hz: float  # MPC_VELD_LP
    vertical_velocity_gain_per_s: float  # MPC_Z_VEL_P_ACC
    vertical_integral_gain_per_s2: float  # MPC_Z_VEL_I_ACC
    horizontal_speed_max_m_s: float  # MPC_XY_VEL_MAX
    climb_max_m_s: float  # MPC_Z_VEL_MAX_UP
    descent_max_m_s: float  # MPC_Z_VEL_MAX_DN
    tilt_max_deg: float  # MPC_TILTMAX_AIR
    thrust_min: float  # MPC_THR_MIN, of the rotors' total
    thrust_xy_margin: float  # MPC_THR_XY_MARG: horizontal thrust the vertical always leaves
    attitude_gain_per_s: float  # MC_ROLL_P = MC_PITCH_P
    rate_gain_per_s: float
    rate_max_rad_s: float
    # between two VISION_POSITION_ESTIMATEs the belief moves by the filter's velocity, the true
    # one plus a constant bias (drawn once a run) and white noise (drawn each step)
    velocity_bias_m_s: float  # sigma of the bias, per axis
    velocity_noise_m_s: float  # sigma of a step's noise, per axis

    def __post_init__(self) -> None:
        _non_negative(self, "velocity_bias_m_s", "velocity_noise_m_s")
        _positive(self, "position_gain_per_s", "vertical_position_gain_per_s")
        _positive(self, "velocity_gain_per_s", "attitude_gain_per_s", "rate_gain_per_s")
        _positive(self, "tilt_max_deg", "rate_max_rad_s", "vertical_velocity_gain_per_s")
        _positive(self, "climb_max_m_s", "descent_max_m_s", "horizontal_speed_max_m_s")
        _positive(self, "velocity_derivative_cutoff_hz")
        _non_negative(self, "velocity_integral_gain_per_s2", "vertical_integral_gain_per_s2")
        _non_negative(self, "velocity_derivative_gain", "thrust_min", "thrust_xy_margin")
        _at_most(self, 0.5, "a share of the rotors' thrust", "thrust_min")
        _require(
            MIN_TILT_DEG <= self.tilt_max_deg <= MAX_TILT_DEG,
            "tilt_max_deg",
            f"must be in [{MIN_TILT_DEG:g}, {MAX_TILT_DEG:g}] degrees (less leaves no sideways "
            "thrust to fly; PX4 allows at most 89)",
        )
        _at_most(self, 1.0, "a navigation filter's velocity error", "velocity_bias_m_s")
        _at_most(self, 1.0, "a navigation filter's velocity error", "velocity_noise_m_s")
        for parameter, name in PX4_PARAMETERS.items():
            _as_parameter(name, getattr(self, name), parameter)

    def tuning(self) -> list[float]:
        """The values of :data:`TUNED_FIELDS`, in order, in the loops' units (the tilt in
        radians): what the compiled loop takes as an input, so that a parameter set in flight
        needs no new compilation."""
        return [
            math.radians(self.tilt_max_deg) if name == "tilt_max_deg" else getattr(self, name)
            for name in TUNED_FIELDS
        ]


# PX4's parameter for each field the vehicle serves and takes in flight
PX4_PARAMETERS: dict[str, str] = {
    "MPC_XY_P": "position_gain_per_s",
    "MPC_Z_P": "vertical_position_gain_per_s",
    "MPC_XY_VEL_P_ACC": "velocity_gain_per_s",
    "MPC_XY_VEL_I_ACC": "velocity_integral_gain_per_s2",
    "MPC_XY_VEL_D_ACC": "velocity_derivative_gain",
    "MPC_Z_VEL_P_ACC": "vertical_velocity_gain_per_s",
    "MPC_Z_VEL_I_ACC": "vertical_integral_gain_per_s2",
    "MPC_XY_VEL_MAX": "horizontal_speed_max_m_s",
    "MPC_Z_VEL_MAX_UP": "climb_max_m_s",
    "MPC_Z_VEL_MAX_DN": "descent_max_m_s",
    "MPC_TILTMAX_AIR": "tilt_max_deg",
    "MPC_THR_MIN": "thrust_min",
    "MPC_THR_XY_MARG": "thrust_xy_margin",
}
TUNED_FIELDS: tuple[str, ...] = tuple(PX4_PARAMETERS.values())
assert set(TUNED_FIELDS) <= {f.name for f in fields(AutopilotSettings)}
