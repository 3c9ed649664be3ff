"""The rigid body of a simulated multicopter: mass, inertia, rotors, their aerodynamics near
surfaces and in moving air, and the rate it is integrated at (docs/model.md, "A multicopter's
dynamics").

The defaults are a ~1.5 kg inspection quadrotor, scaled from PX4's SIH defaults for a 1 kg
quadrotor (``src/modules/simulation/simulator_sih/sih_params.c``: SIH_MASS 1.0 kg,
SIH_IXX/IYY 0.025 and SIH_IZZ 0.03 kg m^2, SIH_T_MAX 5 N and SIH_Q_MAX 0.1 N m per rotor,
SIH_L_ROLL 0.2 m, SIH_KDW 0.025 N m/(rad/s), SIH_T_TAU 0.05 s): mass, inertia, rotor thrust
and torque x 1.5 (the same frame, heavier: thrust-to-weight stays ~2), lever and motor lag as
SIH has them. SIH's SIH_L_ROLL is the roll moment's lever ("half the distance between the left
and right motors"): the rotors of the X sit at (+-L, +-L), sqrt(2) L from the centre.

The air's forces are RotorPy's (spencerfolk/rotorpy, ``rotorpy/vehicles/multirotor.py``) with
its AscTec Hummingbird's constants (``hummingbird_params.py``): each rotor's drag
-omega k_d v_air in the rotor's plane at its hub, omega = sqrt(T / k_eta) the rotor's speed,
and the frame's parasitic drag -|v_air| diag(c_Dx, c_Dy, c_Dz) v_air at the centre of mass,
both in the body frame. RotorPy's inflow term along the rotor's axis (k_z) and its
translational lift (k_h) are left out: the rotors' drag acts in their plane only. SIH's
linear KDV drag is not used (SIH feels no wind).

Near a surface a rotor makes more thrust for the same power (:data:`PROXIMITY_MODELS`):
``measured`` is the ceiling law of Hsiao and Chirarattananon (2019) and the multirotor ground
law of Sanchez-Cuevas, Heredia and Ollero (2017); ``image`` is Cheeseman and Bennett's (1955)
1 / (1 - (R / 4d)^2), above and below; ``none`` switches the effect off.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal, get_args

import numpy as np

from mission.config.checks import non_negative as _non_negative
from mission.config.checks import positive as _positive
from mission.config.checks import require as _require
from mission.config.proximity_laws import ground_gain_denominator

MIN_RATE_HZ = 50.0  # below this the motors' 0.05 s lag is not resolved
STANDARD_GRAVITY = 9.80665
MAX_MASS_KG = 100.0
# rotor angles from the nose toward the left: front-left, rear-left, rear-right, front-right
ROTOR_ANGLES_DEG = (45.0, 135.0, 225.0, 315.0)
ProximityModel = Literal["measured", "image", "none"]
PROXIMITY_MODELS = get_args(ProximityModel)


@dataclass(frozen=True)
class MulticopterSettings:
    """A quadrotor in X configuration, rotors at 45, 135, 225 and 315 degrees from the nose,
    spinning alternately (front-right counter-clockwise)."""

    mass_kg: float
    inertia_kg_m2: tuple[float, float, float]  # Ixx, Iyy, Izz (body)
    lever_m: float  # SIH_L_ROLL = SIH_L_PITCH: half the distance between left and right rotors
    rotor_height_m: float  # the rotors' plane above the centre of mass
    rotor_thrust_max_n: float  # one rotor at full command
    rotor_torque_max_n_m: float  # its reaction torque at full command
    motor_tau_s: float  # first-order lag of a rotor's thrust
    rotor_thrust_coefficient: float  # k_eta, N/(rad/s)^2: a rotor's speed sqrt(T / k_eta)
    rotor_drag_coefficient: float  # k_d, kg/rad: drag in the rotor's plane, -omega k_d v_air
    parasitic_drag_n_s2_m2: tuple[float, float, float]  # c_D, body x, y, z: -|v| c_D v
    rotational_damping_n_m_per_rad_s: float  # -k omega, as SIH's KDW
    rate_hz: float  # fixed integration rate within each step
    rotor_radius_m: float
    ceiling_model: ProximityModel  # the thrust gain under a surface
    ground_model: ProximityModel  # ... over one
    proximity_clip_radii: float  # closer than this (rotor radii) the gain stays as it is there

    def __post_init__(self) -> None:
        _positive(self, "mass_kg", "lever_m", "rotor_thrust_max_n", "motor_tau_s", "rate_hz")
        _positive(self, "rotor_radius_m", "proximity_clip_radii", "rotor_thrust_coefficient")
        _non_negative(self, "rotor_torque_max_n_m", "rotor_height_m")
        _non_negative(self, "rotor_drag_coefficient")
        _non_negative(self, "rotational_damping_n_m_per_rad_s")
        for name, size in (("inertia_kg_m2", "[Ixx, Iyy, Izz]"), ("parasitic_drag_n_s2_m2", "")):
            values = getattr(self, name)
            _require(len(values) == 3, name, f"must be three values {size}".rstrip())
        _require(
            all(value > 0 for value in self.inertia_kg_m2),
            "inertia_kg_m2",
            "must be positive (a body with a zero moment of inertia is singular)",
        )
        _require(
            all(value >= 0 for value in self.parasitic_drag_n_s2_m2),
            "parasitic_drag_n_s2_m2",
            "must not be negative (drag that pushes the body along would feed itself)",
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
        spacing = 2 * self.lever_m  # between neighbouring rotors of an X
        _require(
            2 * self.rotor_radius_m <= spacing,
            "rotor_radius_m",
            f"neighbouring rotors {spacing:.3f} m apart would overlap",
        )
        for name in ("ceiling_model", "ground_model"):
            _require(
                getattr(self, name) in PROXIMITY_MODELS,
                name,
                f"must be one of {', '.join(PROXIMITY_MODELS)}, got {getattr(self, name)!r}",
            )
        self._check_ground_law_finite()

    def _check_ground_law_finite(self) -> None:
        if self.ground_model == "none":
            return
        least = self.proximity_clip_radii * self.rotor_radius_m
        _require(
            ground_gain_denominator(self, least) > 0,
            "proximity_clip_radii",
            f"{self.proximity_clip_radii:g} rotor radii is inside the {self.ground_model} ground "
            "law's singularity: the gain would be infinite there (raise it)",
        )

    @property
    def rotor_arm_m(self) -> float:
        """Each rotor's axis from the centre, horizontally."""
        return math.sqrt(2) * self.lever_m

    def rotor_hubs(self) -> np.ndarray:
        """(4, 3): each rotor's hub in the body frame (FLU, m): at (+-L, +-L), L the lever,
        ``rotor_height_m`` above the centre of mass; front-left, rear-left, rear-right,
        front-right."""
        angles = np.radians(ROTOR_ANGLES_DEG)
        arm, height = self.rotor_arm_m, np.full(4, self.rotor_height_m)
        return np.column_stack([arm * np.cos(angles), arm * np.sin(angles), height])

    @property
    def rotor_tips_m(self) -> float:
        """How far the rotors' tips reach from the centre, horizontally."""
        return self.rotor_arm_m + self.rotor_radius_m

    @property
    def proximity_effects(self) -> bool:
        """Whether a surface above or below changes the rotors' thrust."""
        return self.ceiling_model != "none" or self.ground_model != "none"
