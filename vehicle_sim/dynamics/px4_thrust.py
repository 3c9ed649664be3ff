"""The velocity loop and thrust limits of PX4's multicopter position controller, in ENU and
as casadi expressions (PX4-Autopilot, src/modules/mc_pos_control/PositionControl/
PositionControl.cpp, ``_velocityControl`` and ``_accelerationControl``, and ControlMath.cpp's
``limitTilt``), with thrust normalised to [0, 1] of the rotors' total:

1. acceleration setpoint a = Kp e + integral - Kd dv/dt (e = v_sp - v, dv/dt the filtered
   acceleration), the vertical integral held within +-g (and not integrated further out);
2. thrust direction (a_x, a_y, g) (acceleration and gravity decoupled, PX4's default
   MPC_ACC_DECOUPLE), tilted back to the tilt limit where it leans further;
3. the vertical thrust T_z = hover (1 + a_z / g), the thrust along the direction
   T_z / cos(tilt), at least the minimum thrust;
4. vertical priority: the vertical thrust keeps all but a horizontal margin
   (MPC_THR_XY_MARG) below the maximum, the horizontal thrust what is left;
5. anti-windup: the vertical error stops integrating while the vertical thrust is at a
   limit in its direction (conditional integration), the horizontal error is reduced by what
   the limits took off the acceleration (tracking, gain 2 / Kp). PX4 reckons the acceleration
   the limited thrust makes as T_xy g / T_hover with its hover thrust estimate (MPC_USE_HTE);
   that estimate converges to the vertical thrust the vehicle needs, so here it is that
   vertical thrust, T_xy g / T_z (with T_hover from the mass alone, a body whose drag lifts
   it would read its own tilt as saturated and stop integrating short of its place).

Returns the thrust vector (normalised) and the integral's rate.
"""

from __future__ import annotations

import casadi as ca

from mission.config.multicopter_settings import STANDARD_GRAVITY

TINY = 1e-9


def limit_tilt(direction: ca.SX, tilt_max_rad: float) -> ca.SX:
    """The unit ``direction`` turned towards up until it leans at most ``tilt_max_rad``."""
    horizontal = ca.norm_2(direction[:2])
    tilt = ca.atan2(horizontal, direction[2])
    allowed = ca.fmin(tilt, tilt_max_rad)
    scale = ca.sin(allowed) / (horizontal + TINY)
    return ca.vertcat(direction[0] * scale, direction[1] * scale, ca.cos(allowed))


def thrust_setpoint(
    error: ca.SX,
    integral: ca.SX,
    damping: ca.SX,
    hover: float,
    gains: tuple[float, float, float, float],
    limits: tuple[float, float, float, float],
) -> tuple[ca.SX, ca.SX]:
    """(normalised thrust vector, d(integral)/dt) for velocity error ``error`` (ENU) and
    the derivative term ``damping`` (Kd dv/dt, subtracted); ``gains`` (Kp_xy, Kp_z, Ki_xy,
    Ki_z), ``limits`` (tilt_max_rad, thr_min, thr_max, xy_margin)."""
    kp_xy, kp_z, ki_xy, ki_z = gains
    tilt_max, thr_min, thr_max, margin = limits
    g = STANDARD_GRAVITY
    kp = ca.vertcat(kp_xy, kp_xy, kp_z)
    held_z = ca.fmin(ca.fmax(integral[2], -g), g)  # PX4 holds the vertical integral within g
    integral = ca.vertcat(integral[0], integral[1], held_z)
    acceleration = kp * error + integral - damping
    direction = ca.vertcat(acceleration[0], acceleration[1], g)
    direction = limit_tilt(direction / ca.norm_2(direction), tilt_max)
    vertical = hover * (1 + acceleration[2] / g)
    along = ca.fmax(vertical / direction[2], thr_min)
    thrust = direction * along
    # vertical anti-windup before the vertical priority's clamp, as PX4 does
    error_z = ca.if_else(
        ca.logic_or(
            ca.logic_and(thrust[2] <= thr_min, error[2] <= 0),
            ca.logic_and(thrust[2] >= thr_max, error[2] >= 0),
        ),
        0,
        error[2],
    )
    horizontal = thrust[:2]
    allocated = ca.fmin(ca.norm_2(horizontal), margin)
    thrust_z = ca.fmin(thrust[2], ca.sqrt(thr_max**2 - allocated**2))
    room = ca.sqrt(ca.fmax(thr_max**2 - thrust_z**2, 0))
    size = ca.norm_2(horizontal)
    horizontal = horizontal * ca.fmin(1, room / (size + TINY))
    thrust = ca.vertcat(horizontal, thrust_z)
    produced = horizontal * g / ca.fmax(thrust_z, TINY)
    wanted = acceleration[:2]
    excess = ca.if_else(ca.sumsqr(wanted) > ca.sumsqr(produced), wanted - produced, [0, 0])
    error_xy = error[:2] - 2.0 / kp_xy * excess
    outward = ca.logic_or(
        ca.logic_and(held_z >= g, error_z > 0), ca.logic_and(held_z <= -g, error_z < 0)
    )
    rate = ca.vertcat(ki_xy * error_xy, ca.if_else(outward, 0, ki_z * error_z))
    return thrust, rate
