"""The rigid body of a simulated multicopter: mass, inertia, rotors, drag, and the
rate it is integrated at.

The defaults are a ~1.5 kg inspection quadrotor, scaled from PX4's SIH defaults for a 1 kg
quadrotor (``src/modules/simulation/simulator_sih/sih_params.yaml``: SIH_MASS 1.0 kg,
SIH_IXX/IYY 0.025 and SIH_IZZ 0.03 kg m^2, SIH_T_MAX 5 N and SIH_Q_MAX 0.1 N m per rotor,
SIH_L_ROLL 0.2 m, SIH_KDV 1.0 N/(m/s), SIH_KDW 0.025 N m/(rad/s), SIH_T_TAU 0.05 s): mass,
inertia, rotor thrust and torque x 1.5 (the same frame, heavier: thrust-to-weight stays ~2),
arm, drag and motor lag as SIH has them. SIH has no propellers' size: the rotor radius is a
10-inch propeller's, the size a 450-class frame with 0.2 m arms carries.

Near a surface a rotor makes more thrust for the same power: the ground effect below
(Cheeseman and Bennett 1955: T/T0 = 1 / (1 - (R / 4z)^2), R the rotor radius, z the height)
and, by the same image argument, the ceiling effect under a deck (docs/model.md). Both are
T/T0 = 1 / (1 - k (R / d)^2) with d the distance from the rotor to the surface and k = 1/16,
held at its value at ``proximity_clip_radii`` closer in (the law diverges at d = R sqrt(k)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from mission.config.checks import at_most as _at_most
from mission.config.checks import non_negative as _non_negative
from mission.config.checks import positive as _positive
from mission.config.checks import require as _require

MIN_RATE_HZ = 50.0  # below this the motors' 0.05 s lag is not resolved
STANDARD_GRAVITY = 9.80665
MAX_MASS_KG = 100.0
MIN_TILT_DEG = 5.0


@dataclass(frozen=True)
class MulticopterSettings:
    """A quadrotor in X configuration, rotors at 45, 135, 225 and 315 degrees from the nose,
    spinning alternately (front-right counter-clockwise)."""

    mass_kg: float
    inertia_kg_m2: tuple[float, float, float]  # Ixx, Iyy, Izz (body)
    arm_m: float  # centre to each rotor's axis
    rotor_thrust_max_n: float  # one rotor at full command
    rotor_torque_max_n_m: float  # its reaction torque at full command
    motor_tau_s: float  # first-order lag of a rotor's thrust
    drag_n_per_m_s: float  # body drag -k (v - wind), as SIH's KDV
    rotational_damping_n_m_per_rad_s: float  # -k omega, as SIH's KDW
    rate_hz: float  # fixed integration rate within each step
    rotor_radius_m: float
    ceiling_effect_k: float  # T/T0 = 1 / (1 - k (R/d)^2) under a surface (0: none)
    ground_effect_k: float  # ... above one
    proximity_clip_radii: float  # closer than this (rotor radii) the gain stays as it is there

    def __post_init__(self) -> None:
        _positive(self, "mass_kg", "arm_m", "rotor_thrust_max_n", "motor_tau_s", "rate_hz")
        _positive(self, "rotor_radius_m", "proximity_clip_radii")
        _non_negative(self, "ceiling_effect_k", "ground_effect_k")
        _non_negative(self, "rotor_torque_max_n_m", "drag_n_per_m_s")
        _non_negative(self, "rotational_damping_n_m_per_rad_s")
        _require(len(self.inertia_kg_m2) == 3, "inertia_kg_m2", "must be [Ixx, Iyy, Izz]")
        _require(
            all(value > 0 for value in self.inertia_kg_m2),
            "inertia_kg_m2",
            "must be positive (a body with a zero moment of inertia is singular)",
        )
        ixx, iyy, izz = self.inertia_kg_m2
        _require(
            ixx + iyy >= izz and iyy + izz >= ixx and izz + ixx >= iyy,
            "inertia_kg_m2",
            "breaks the triangle inequality of a rigid body's principal moments",
        )
        _require(self.rate_hz >= MIN_RATE_HZ, "rate_hz", f"must be at least {MIN_RATE_HZ:g} Hz")
        _require(self.mass_kg <= MAX_MASS_KG, "mass_kg", f"must be at most {MAX_MASS_KG:g} kg")
        hover = self.mass_kg * STANDARD_GRAVITY / 4
        _require(
            self.rotor_thrust_max_n > hover,
            "rotor_thrust_max_n",
            f"must exceed a quarter of the weight ({hover:.2f} N): it could not hover",
        )
        spacing = self.arm_m * math.sqrt(2)  # between neighbouring rotors of an X
        _require(
            2 * self.rotor_radius_m <= spacing,
            "rotor_radius_m",
            f"neighbouring rotors {spacing:.3f} m apart would overlap",
        )
        for name in ("ceiling_effect_k", "ground_effect_k"):
            _require(
                getattr(self, name) < self.proximity_clip_radii**2,
                name,
                f"must be below proximity_clip_radii^2 ({self.proximity_clip_radii**2:g}): "
                "the thrust gain would be infinite within the clip distance",
            )

    @property
    def proximity_effects(self) -> bool:
        """Whether a surface above or below changes the rotors' thrust."""
        return self.ceiling_effect_k > 0 or self.ground_effect_k > 0


@dataclass(frozen=True)
class AutopilotSettings:
    """The position controller's cascade, as ArduPilot's and PX4's multicopter controllers
    run it: position error -> velocity setpoint (capped at the speed limit) -> acceleration
    setpoint (capped) -> thrust vector (tilt capped) -> attitude -> body rates -> rotor
    thrusts. Each gain is the inverse of its loop's time constant; the defaults put the
    loops a factor ~2.5-4 apart (PX4's MPC_XY_P 0.95, MPC_XY_VEL_P_ACC 1.8, MC_ROLL_P 6.5)."""

    position_gain_per_s: float
    velocity_gain_per_s: float  # MPC_XY_VEL_P_ACC
    velocity_integral_gain_per_s2: float  # MPC_XY_VEL_I_ACC
    vertical_velocity_gain_per_s: float  # MPC_Z_VEL_P_ACC
    vertical_integral_gain_per_s2: float  # MPC_Z_VEL_I_ACC
    attitude_gain_per_s: float
    rate_gain_per_s: float
    thrust_min: float  # MPC_THR_MIN, of the rotors' total
    thrust_xy_margin: float  # MPC_THR_XY_MARG: horizontal thrust the vertical always leaves
    climb_max_m_s: float  # MPC_Z_VEL_MAX_UP
    descent_max_m_s: float  # MPC_Z_VEL_MAX_DN
    tilt_max_deg: float
    rate_max_rad_s: float
    # between two VISION_POSITION_ESTIMATEs the belief moves by the filter's velocity, the true
    # one plus a constant bias (drawn once a run) and white noise (drawn each step)
    velocity_bias_m_s: float  # sigma of the bias, per axis
    velocity_noise_m_s: float  # sigma of a step's noise, per axis

    def __post_init__(self) -> None:
        _non_negative(self, "velocity_bias_m_s", "velocity_noise_m_s")
        _positive(self, "position_gain_per_s", "velocity_gain_per_s", "attitude_gain_per_s")
        _positive(self, "rate_gain_per_s", "tilt_max_deg", "rate_max_rad_s")
        _positive(self, "vertical_velocity_gain_per_s", "climb_max_m_s", "descent_max_m_s")
        _non_negative(self, "velocity_integral_gain_per_s2", "vertical_integral_gain_per_s2")
        _non_negative(self, "thrust_min", "thrust_xy_margin")
        _at_most(self, 0.5, "a share of the rotors' thrust", "thrust_min")
        _at_most(self, 0.9, "a share of the rotors' thrust", "thrust_xy_margin")
        _require(
            MIN_TILT_DEG <= self.tilt_max_deg < 90,
            "tilt_max_deg",
            f"must be in [{MIN_TILT_DEG:g}, 90) degrees (less leaves no sideways thrust to fly)",
        )
        _at_most(self, 1.0, "a navigation filter's velocity error", "velocity_bias_m_s")
        _at_most(self, 1.0, "a navigation filter's velocity error", "velocity_noise_m_s")
