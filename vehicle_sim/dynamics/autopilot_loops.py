"""The autopilot's position controller for the rigid body (docs/model.md, "A multicopter's
dynamics"), as casadi expressions run at the integration rate: PX4's multicopter cascade.

1. position error (from where the autopilot *believes* it is) -> velocity setpoint: the
   setpoint's velocity feed-forward plus PX4's MPC_XY_P and MPC_Z_P times the error, the
   horizontal capped by norm at the lower of the guidance's limit and MPC_XY_VEL_MAX (the
   error's share kept first, PX4's ``constrainXY``), the vertical at MPC_Z_VEL_MAX_UP / _DN;
2. velocity error -> acceleration -> thrust vector: PX4's PID with its tilt and thrust limits
   and anti-windup (:mod:`~vehicle_sim.dynamics.px4_thrust`); the derivative acts on the
   velocity's rate of change, low-passed at MPC_VELD_LP (a filter state);
3. the attitude that points the body's z along the thrust at a fixed heading (the formation's
   UAVs do not yaw), its error (the geometric one of Lee, Leok and McClamroch 2010) -> body
   rates, capped;
4. rate error -> moments (with the gyroscopic term), and the collective thrust along the
   current body z; the mixer (:mod:`~vehicle_sim.dynamics.mixer`) turns thrust and moments
   into the four rotors' commands, desaturated as PX4's.

The tunable values (:data:`~mission.config.autopilot_settings.TUNED_FIELDS`) come in as one
input vector, so a parameter set in flight takes effect without a new compilation. The
controller's state is the velocity error's integral (3) and the low-passed velocity (3),
carried after the rigid body's 17.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np

from mission.config.autopilot_settings import TUNED_FIELDS, AutopilotSettings
from mission.config.multicopter_settings import STANDARD_GRAVITY, MulticopterSettings
from vehicle_sim.dynamics.mixer import motor_commands_mixed
from vehicle_sim.dynamics.px4_thrust import thrust_setpoint
from vehicle_sim.dynamics.rigid_body import ATTITUDE, POSITION, RATES, VELOCITY, rotation

TINY = 1e-9
CONTROLLER_SIZE = 6  # the integral (3), the low-passed velocity (3)


def _capped(vector: ca.SX, limit) -> ca.SX:
    """``vector`` scaled down to length ``limit`` where it is longer."""
    return vector * ca.fmin(1, limit / (ca.norm_2(vector) + TINY))


def _tuned(tuning: ca.SX) -> dict[str, ca.SX]:
    return {name: tuning[i] for i, name in enumerate(TUNED_FIELDS)}


def constrain_xy(first: ca.SX, then: ca.SX, limit: ca.SX) -> ca.SX:
    """PX4's ``ControlMath::constrainXY``: ``first + then`` within ``limit`` by norm,
    ``first`` (the position error's share) kept before ``then`` (the feed-forward)."""
    both = first + then
    size_first = ca.norm_2(first)
    direction = then / (ca.norm_2(then) + TINY)
    m = ca.dot(direction, first)
    c = ca.sumsqr(first) - limit**2
    along = -m + ca.sqrt(ca.fmax(m**2 - c, 0))
    return ca.if_else(
        ca.norm_2(both) <= limit,
        both,
        ca.if_else(
            size_first >= limit, first * limit / (size_first + TINY), first + along * direction
        ),
    )


def velocity_setpoint(
    tune: dict[str, ca.SX], believed: ca.SX, target: ca.SX, speed_limit: ca.SX, feedforward: ca.SX
) -> ca.SX:
    """PX4's position loop: the feed-forward plus the position error's velocity, each
    direction within its limits (the error's share first)."""
    error = target - believed
    limit = ca.fmin(speed_limit, tune["horizontal_speed_max_m_s"])
    horizontal = constrain_xy(tune["position_gain_per_s"] * error[:2], feedforward[:2], limit)
    vertical = feedforward[2] + tune["vertical_position_gain_per_s"] * error[2]
    vertical = ca.fmin(ca.fmax(vertical, -tune["descent_max_m_s"]), tune["climb_max_m_s"])
    return ca.vertcat(horizontal, vertical)


def motor_commands(
    body: MulticopterSettings,
    loops: AutopilotSettings,
    state: ca.SX,
    controller: ca.SX,
    inputs: tuple[ca.SX, ca.SX, ca.SX, ca.SX, ca.SX],
) -> tuple[ca.SX, ca.SX]:
    """(the rotors' commands, d(controller state)/dt) for this state; ``inputs`` are the
    position target, the belief's offset from the truth, the guidance's speed limit, the
    tuning vector and the setpoint's velocity feed-forward."""
    target, belief_offset, speed_limit, tuning, feedforward = inputs
    tune = _tuned(tuning)
    velocity, q, rates = state[VELOCITY], state[ATTITUDE], state[RATES]
    integral, smoothed = controller[:3], controller[3:]
    believed = state[POSITION] + belief_offset
    wanted = velocity_setpoint(tune, believed, target, speed_limit, feedforward)
    cutoff = 2 * math.pi * loops.velocity_derivative_cutoff_hz
    acceleration = cutoff * (velocity - smoothed)  # d/dt of the velocity, low-passed
    damping = tune["velocity_derivative_gain"] * ca.vertcat(acceleration[:2], 0)
    hover = body.mass_kg * STANDARD_GRAVITY / (4 * body.rotor_thrust_max_n)
    gains = tuple(
        tune[name]
        for name in (
            "velocity_gain_per_s",
            "vertical_velocity_gain_per_s",
            "velocity_integral_gain_per_s2",
            "vertical_integral_gain_per_s2",
        )
    )
    limits = (tune["tilt_max_deg"], tune["thrust_min"], 1.0, tune["thrust_xy_margin"])
    thrust, integral_rate = thrust_setpoint(
        wanted - velocity, integral, damping, hover, gains, limits
    )
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
    commands = motor_commands_mixed(body, ca.vertcat(collective, moment))
    return commands, ca.vertcat(integral_rate, acceleration)
