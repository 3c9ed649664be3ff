"""A quadrotor as a rigid body with four lagged rotors (docs/model.md, "A multicopter's
dynamics"), as casadi expressions: its state's derivative and one integration substep, which
:mod:`~vehicle_sim.dynamics.closed_loop` folds with the autopilot's loops over a whole
simulation step in one Function call.

The rigid body and rotors are PX4 SIH's (``simulator_sih/sih.cpp``): thrust along the body's z
axis from four rotors whose thrust follows the command with a first-order lag
(``motor_tau_s``), moments from the rotors' levers and their reaction torques, linear
rotational damping (``-k omega``), gravity. The rotors sit at (+-L, +-L) in the body's x-y
plane, ``rotor_height_m`` above the centre of mass. The air's forces are RotorPy's
(``rotorpy/vehicles/multirotor.py``): each rotor's drag -omega_i k_d v_i in the rotor's plane
at its hub, v_i the air's velocity there (the body's velocity less the wind, plus its rotation's),
omega_i = sqrt(T_i / k_eta); and the frame's quadratic parasitic drag at the centre of mass.
A hub's drag above the centre of mass also pitches the body. Frames: ENU world, FLU body (x
nose, y left, z up); the attitude is the unit quaternion (w, x, y, z) taking body to world.

Near a surface each rotor's thrust is multiplied by the ceiling or ground law's gain
(:mod:`mission.config.proximity_laws`) for its own distance to the surface above or below it:
a body tilted under a deck makes more thrust on its upper side, and a moment. The rotors'
reaction torque and drag stay as their speed makes them (the law holds the rotor's power).

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
from mission.config.proximity_laws import ceiling_gain, ground_gain

STATE_SIZE = 17
POSITION, VELOCITY, ATTITUDE, RATES, THRUSTS = (
    slice(0, 3),
    slice(3, 6),
    slice(6, 10),
    slice(10, 13),
    slice(13, 17),
)
# each rotor's spin: +1 counter-clockwise seen from above (PX4's quad X: front-right and
# rear-left counter-clockwise; the rotors' angles: multicopter_settings.ROTOR_ANGLES_DEG)
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


def near_surfaces(settings: MulticopterSettings, state: ca.SX, surfaces: ca.SX) -> ca.SX:
    """(4,) each rotor's thrust gain under the surface above it and over the one below
    (``surfaces``: the four rotors' heights above, then below)."""
    s = settings
    heights = state[2] + (rotation(state[ATTITUDE]) @ ca.DM(s.rotor_hubs().T))[2, :].T
    above = ceiling_gain(s, surfaces[:4] - heights, ca.fmax)
    below = ground_gain(s, heights - surfaces[4:], ca.fmax)
    return above * below


def air_forces(settings: MulticopterSettings, state: ca.SX, wind: ca.SX) -> tuple[ca.SX, ca.SX]:
    """(force, moment) of the air on the body, both in the body frame: the rotors' drag at
    their hubs and the frame's parasitic drag (RotorPy's model)."""
    s = settings
    velocity, q, rates, thrusts = (state[part] for part in (VELOCITY, ATTITUDE, RATES, THRUSTS))
    air = rotation(q).T @ (velocity - wind)  # the body's velocity through the air, body frame
    drag = -ca.norm_2(air) * ca.DM(s.parasitic_drag_n_s2_m2) * air
    moment = ca.DM.zeros(3)
    in_plane = ca.DM([s.rotor_drag_coefficient, s.rotor_drag_coefficient, 0.0])
    for hub, thrust in zip(s.rotor_hubs(), ca.vertsplit(thrusts)):
        speed = ca.sqrt(ca.fmax(thrust, 0) / s.rotor_thrust_coefficient)
        hub_force = -speed * in_plane * (air + ca.cross(rates, ca.DM(hub)))
        drag += hub_force
        moment += ca.cross(ca.DM(hub), hub_force)
    return drag, moment


def hover_drag(settings: MulticopterSettings, wind: np.ndarray) -> np.ndarray:
    """(3,) the air's force (N, world) on the body hovering level and still in ``wind``."""
    state = ca.SX.sym("x", STATE_SIZE)
    air = ca.SX.sym("w", 3)
    drag = ca.Function("drag", [state, air], [air_forces(settings, state, air)[0]])
    resting = resting_state(np.zeros(3), settings)
    return np.asarray(drag(resting, np.asarray(wind, dtype=float))).ravel()


def derivative(
    settings: MulticopterSettings, state: ca.SX, command: ca.SX, wind: ca.SX, gains: ca.SX | None
):
    """d(state)/dt of the rigid body under the rotors' ``command`` (clipped to 0..1), each
    rotor's thrust times its ``gains`` near surfaces (None: away from any)."""
    s = settings
    velocity, q, rates, thrusts = (state[part] for part in (VELOCITY, ATTITUDE, RATES, THRUSTS))
    lifting = thrusts if gains is None else thrusts * gains
    inertia = ca.DM(np.diag(s.inertia_kg_m2))
    drag, moment = air_forces(s, state, wind)
    force = rotation(q) @ (ca.vertcat(0, 0, ca.sum1(lifting)) + drag)
    force -= ca.vertcat(0, 0, s.mass_kg * STANDARD_GRAVITY)
    torque_per_thrust = s.rotor_torque_max_n_m / s.rotor_thrust_max_n
    moment -= s.rotational_damping_n_m_per_rad_s * rates
    for (arm_x, arm_y, _), spin, lift, thrust in zip(
        s.rotor_hubs(), ROTOR_SPINS, ca.vertsplit(lifting), ca.vertsplit(thrusts)
    ):
        # the lever's moment (r x F for F along body z) and the reaction to the rotor's spin
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
