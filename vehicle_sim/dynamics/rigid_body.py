"""A quadrotor as a rigid body with four lagged rotors (docs/model.md, "A multicopter's
dynamics"), as casadi expressions: its state's derivative and one integration substep, which
:mod:`~vehicle_sim.dynamics.closed_loop` folds with the autopilot's loops over a whole
simulation step in one Function call.

The model is PX4 SIH's (``simulator_sih/sih.cpp``): thrust along the body's z axis from four
rotors whose thrust follows the command with a first-order lag (``motor_tau_s``), moments from
the rotors' arms and their reaction torques, linear body drag against the air's velocity
(``-k (v - wind)``) and linear rotational damping (``-k omega``), gravity. Frames: ENU world,
FLU body (x nose, y left, z up); the attitude is the unit quaternion (w, x, y, z) taking body
to world.

Near a surface each rotor's thrust is multiplied by the ceiling or ground effect's gain
(:class:`~mission.config.multicopter_settings.MulticopterSettings`) for its own distance to the
surface above or below it (the rotors lie in the body's x-y plane through its centre): a body
tilted under a deck makes more thrust on its upper side, and a moment. The rotors' reaction
torque stays as commanded (the law holds the rotor's power: its torque does not change).

State (17): position (3, m), velocity (3, m/s), attitude (4), body rates (3, rad/s), rotor
thrusts (4, N, away from surfaces). Inputs over a step: the rotors' commands (4, 0..1), the
wind (3, m/s, world) and the heights of the surfaces above and below each rotor (8, m), held
over each substep; so are the gains, from the rotors' heights as the substep starts. A step
of ``step_s`` is cut into the fewest equal substeps at ``rate_hz`` or faster, each a classical
Runge-Kutta step with the attitude renormalised after it, so the same state and inputs give
the same result bit for bit.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np

from mission.config.multicopter_settings import STANDARD_GRAVITY, MulticopterSettings

STATE_SIZE = 17
POSITION, VELOCITY, ATTITUDE, RATES, THRUSTS = (
    slice(0, 3),
    slice(3, 6),
    slice(6, 10),
    slice(10, 13),
    slice(13, 17),
)
# rotor angles from the nose toward the left, and spin: +1 counter-clockwise seen from above
# (PX4's quad X: front-right and rear-left counter-clockwise)
ROTOR_ANGLES_DEG = (45.0, 135.0, 225.0, 315.0)
ROTOR_SPINS = (-1.0, 1.0, -1.0, 1.0)
SURFACES_SIZE = 8  # the heights of the surface above each rotor, then below each
OPEN_AIR = np.array([1.0e6] * 4 + [-1.0e6] * 4)  # nothing near: no gain worth the name


def rotation(q: ca.SX) -> ca.SX:
    """The rotation matrix of a unit quaternion (w, x, y, z), body to world."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    return ca.vertcat(
        ca.horzcat(1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)),
        ca.horzcat(2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)),
        ca.horzcat(2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)),
    )


def rotor_offsets(settings: MulticopterSettings) -> np.ndarray:
    """(4, 3): each rotor's centre in the body frame (FLU, m)."""
    angles = np.radians(ROTOR_ANGLES_DEG)
    return settings.arm_m * np.column_stack([np.cos(angles), np.sin(angles), np.zeros(4)])


def proximity_gain(k: float, radius_m: float, clip_radii: float, distance_m):
    """A rotor's thrust gain ``distance_m`` from a surface: 1 / (1 - k (R/d)^2), d held at
    ``clip_radii`` rotor radii closer in (a casadi expression; numbers give a casadi DM)."""
    held = ca.fmax(distance_m, clip_radii * radius_m)
    return 1 / (1 - k * (radius_m / held) ** 2)


def near_surfaces(settings: MulticopterSettings, state: ca.SX, surfaces: ca.SX) -> ca.SX:
    """(4,) each rotor's thrust gain under the surface above it and over the one below
    (``surfaces``: the four rotors' heights above, then below)."""
    s = settings
    heights = state[2] + (rotation(state[ATTITUDE]) @ ca.DM(rotor_offsets(s).T))[2, :].T
    gain = ca.DM.ones(4)
    for k, gap in (
        (s.ceiling_effect_k, surfaces[:4] - heights),
        (s.ground_effect_k, heights - surfaces[4:]),
    ):
        if k > 0:
            gain = gain * proximity_gain(k, s.rotor_radius_m, s.proximity_clip_radii, gap)
    return gain


def derivative(
    settings: MulticopterSettings, state: ca.SX, command: ca.SX, wind: ca.SX, gains: ca.SX | None
):
    """d(state)/dt of the rigid body under the rotors' ``command`` (clipped to 0..1), each
    rotor's thrust times its ``gains`` near surfaces (None: away from any)."""
    s = settings
    velocity, q, rates, thrusts = (state[part] for part in (VELOCITY, ATTITUDE, RATES, THRUSTS))
    lifting = thrusts if gains is None else thrusts * gains
    inertia = ca.DM(np.diag(s.inertia_kg_m2))
    force = rotation(q) @ ca.vertcat(0, 0, ca.sum1(lifting))
    force += -s.drag_n_per_m_s * (velocity - wind) - ca.vertcat(0, 0, s.mass_kg * STANDARD_GRAVITY)
    torque_per_thrust = s.rotor_torque_max_n_m / s.rotor_thrust_max_n
    moment = -s.rotational_damping_n_m_per_rad_s * rates
    for angle, spin, lift, thrust in zip(
        ROTOR_ANGLES_DEG, ROTOR_SPINS, ca.vertsplit(lifting), ca.vertsplit(thrusts)
    ):
        arm_x = s.arm_m * math.cos(math.radians(angle))
        arm_y = s.arm_m * math.sin(math.radians(angle))
        # the arm's moment (r x F for F along body z) and the reaction to the rotor's spin
        moment += ca.vertcat(arm_y * lift, -arm_x * lift, -spin * torque_per_thrust * thrust)
    angular = ca.solve(inertia, moment - ca.cross(rates, inertia @ rates))
    spin_rate = 0.5 * ca.vertcat(
        -q[1] * rates[0] - q[2] * rates[1] - q[3] * rates[2],
        q[0] * rates[0] + q[2] * rates[2] - q[3] * rates[1],
        q[0] * rates[1] - q[1] * rates[2] + q[3] * rates[0],
        q[0] * rates[2] + q[1] * rates[1] - q[2] * rates[0],
    )
    wanted = s.rotor_thrust_max_n * ca.fmin(ca.fmax(command, 0), 1)
    lag = (wanted - thrusts) / s.motor_tau_s
    return ca.vertcat(velocity, force / s.mass_kg, spin_rate, angular, lag)


def runge_kutta_substep(
    settings: MulticopterSettings,
    state: ca.SX,
    command: ca.SX,
    wind: ca.SX,
    surfaces: ca.SX,
    h: float,
) -> ca.SX:
    """The state ``h`` seconds on (a classical Runge-Kutta step, ``command``, ``wind`` and the
    rotors' gains near the ``surfaces`` as the substep starts held), its attitude
    renormalised."""
    gains = near_surfaces(settings, state, surfaces) if settings.proximity_effects else None
    held = (command, wind, gains)
    k1 = derivative(settings, state, *held)
    k2 = derivative(settings, state + h / 2 * k1, *held)
    k3 = derivative(settings, state + h / 2 * k2, *held)
    k4 = derivative(settings, state + h * k3, *held)
    after = state + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    q = after[ATTITUDE]
    return ca.vertcat(after[:6], q / ca.norm_2(q), after[10:])


def substeps_of(step_s: float, rate_hz: float) -> int:
    """The fewest equal substeps of ``step_s`` at ``rate_hz`` or faster."""
    return max(1, math.ceil(step_s * rate_hz - 1e-9))


def resting_state(
    position: np.ndarray, settings: MulticopterSettings, tilt: np.ndarray | None = None
) -> np.ndarray:
    """A state at ``position``, at rest, level (or at the attitude quaternion ``tilt``), each
    rotor already making a quarter of the weight (divided by the tilt's cosine)."""
    q = np.array([1.0, 0.0, 0.0, 0.0]) if tilt is None else np.asarray(tilt, dtype=float)
    up = 1 - 2 * (q[1] ** 2 + q[2] ** 2)  # the body z axis' vertical component
    thrust = settings.mass_kg * STANDARD_GRAVITY / 4 / up
    position = np.asarray(position, dtype=float)
    return np.concatenate([position, np.zeros(3), q, np.zeros(3), [thrust] * 4])
