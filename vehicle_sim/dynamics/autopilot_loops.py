"""The autopilot's position controller for the rigid body (docs/model.md, "A multicopter's
dynamics"), as casadi expressions run at the integration rate: the cascade ArduPilot's and
PX4's multicopter controllers use.

1. position error (from where the autopilot *believes* it is) -> velocity setpoint, capped
   at the speed limit;
2. velocity error -> acceleration setpoint, proportional and integral (the integral holds
   against steady wind; it grows only while the acceleration is below its limit), plus the
   drag the setpoint velocity will meet, then capped;
3. the thrust vector m (a + g z) with its tilt capped, and the attitude that points the body's
   z along it at a fixed heading (the formation's UAVs do not yaw);
4. attitude error (the geometric one of Lee, Leok and McClamroch 2010) -> body-rate
   setpoint, capped;
5. rate error -> moments (with the gyroscopic term), and the collective thrust along the
   current body z; the mixer turns thrust and moments into the four rotors' thrusts.

The controller's state is the velocity error's integral (3 values), carried after the rigid
body's 17.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np

from mission.config.multicopter_settings import (
    STANDARD_GRAVITY,
    AutopilotSettings,
    MulticopterSettings,
)
from vehicle_sim.dynamics.px4_thrust import thrust_setpoint
from vehicle_sim.dynamics.rigid_body import (
    ATTITUDE,
    POSITION,
    RATES,
    ROTOR_ANGLES_DEG,
    ROTOR_SPINS,
    VELOCITY,
    rotation,
)

TINY = 1e-9


def mixer(body: MulticopterSettings) -> np.ndarray:
    """(4, 4): the rotors' thrusts from [collective thrust, roll, pitch and yaw moments]."""
    per_thrust = body.rotor_torque_max_n_m / body.rotor_thrust_max_n
    columns = []
    for angle, spin in zip(ROTOR_ANGLES_DEG, ROTOR_SPINS):
        x = body.arm_m * math.cos(math.radians(angle))
        y = body.arm_m * math.sin(math.radians(angle))
        columns.append([1.0, y, -x, -spin * per_thrust])
    return np.linalg.inv(np.array(columns).T)


def _capped(vector: ca.SX, limit) -> ca.SX:
    """``vector`` scaled down to length ``limit`` where it is longer."""
    return vector * ca.fmin(1, limit / (ca.norm_2(vector) + TINY))


def motor_commands(
    body: MulticopterSettings,
    loops: AutopilotSettings,
    state: ca.SX,
    integral: ca.SX,
    target: ca.SX,
    belief_offset: ca.SX,
    speed_limit: ca.SX,
) -> tuple[ca.SX, ca.SX]:
    """(the rotors' commands 0..1, d(integral)/dt) for this state and position target."""
    mass, g = body.mass_kg, STANDARD_GRAVITY
    believed = state[POSITION] + belief_offset
    velocity, q, rates = state[VELOCITY], state[ATTITUDE], state[RATES]
    wanted = loops.position_gain_per_s * (target - believed)
    # PX4: the horizontal speed capped by norm, the vertical by the climb and descent limits
    horizontal_velocity = _capped(wanted[:2], speed_limit)
    vertical_velocity = ca.fmin(ca.fmax(wanted[2], -loops.descent_max_m_s), loops.climb_max_m_s)
    error = ca.vertcat(horizontal_velocity, vertical_velocity) - velocity
    hover = mass * g / (4 * body.rotor_thrust_max_n)
    gains = (
        loops.velocity_gain_per_s,
        loops.vertical_velocity_gain_per_s,
        loops.velocity_integral_gain_per_s2,
        loops.vertical_integral_gain_per_s2,
    )
    limits = (math.radians(loops.tilt_max_deg), loops.thrust_min, 1.0, loops.thrust_xy_margin)
    thrust, integral_rate = thrust_setpoint(error, integral, hover, gains, limits)
    force = thrust * 4 * body.rotor_thrust_max_n
    z_axis = force / ca.norm_2(force)
    y_axis = ca.cross(z_axis, ca.DM([1.0, 0.0, 0.0]))
    y_axis = y_axis / ca.norm_2(y_axis)
    wanted_attitude = ca.horzcat(ca.cross(y_axis, z_axis), y_axis, z_axis)
    current = rotation(q)
    skew = wanted_attitude.T @ current - current.T @ wanted_attitude
    attitude_error = 0.5 * ca.vertcat(skew[2, 1], skew[0, 2], skew[1, 0])
    wanted_rates = -loops.attitude_gain_per_s * attitude_error
    wanted_rates = ca.fmin(ca.fmax(wanted_rates, -loops.rate_max_rad_s), loops.rate_max_rad_s)
    inertia = ca.DM(np.diag(body.inertia_kg_m2))
    moment = inertia @ (loops.rate_gain_per_s * (wanted_rates - rates))
    moment += ca.cross(rates, inertia @ rates)
    collective = ca.dot(force, current[:, 2])
    thrusts = ca.DM(mixer(body)) @ ca.vertcat(collective, moment)
    return thrusts / body.rotor_thrust_max_n, integral_rate
