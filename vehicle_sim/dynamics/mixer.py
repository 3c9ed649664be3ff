"""The mixer: the rotors' commands from the collective thrust and the three moments, with
PX4's desaturation when a rotor would be asked for more than it has or less than nothing
(PX4-Autopilot, ``src/lib/control_allocation/control_allocation/
ControlAllocationSequentialDesaturation.cpp``, with ``MC_AIRMODE`` 0, its default):

1. mix thrust, roll and pitch; take thrust off (never add it) until no rotor is above its
   maximum or below zero, or as far as that goes;
2. then shift along roll, then along pitch, to bring the rotors back within their range
   (attitude authority is kept by giving up some of a moment rather than clipping a rotor);
3. add yaw, shifted along yaw against a maximum raised by 15 % (PX4's MINIMUM_YAW_MARGIN), and
   take thrust off again if a rotor is still above its maximum.

What is left outside [0, 1] the rotors clip (PX4 clips the actuators last as well).

Each shift is PX4's ``desaturateActuators``: the gain that brings the worst rotors to their
limits (``computeDesaturationGain``: the most negative and most positive of them, added),
then half of what is left. Commands are the rotors' thrusts over their maximum (SIH's linear
rotors).
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np

from mission.config.multicopter_settings import MulticopterSettings
from vehicle_sim.dynamics.rigid_body import ROTOR_SPINS

YAW_MARGIN = 0.15  # PX4's MINIMUM_YAW_MARGIN


def allocation(body: MulticopterSettings) -> np.ndarray:
    """(4, 4): the rotors' thrusts (N) from [collective thrust (N), roll, pitch and yaw
    moments (N m)]: the inverse of what the thrusts make."""
    per_thrust = body.rotor_torque_max_n_m / body.rotor_thrust_max_n
    offsets = body.rotor_hubs()
    columns = [[1.0, y, -x, -spin * per_thrust] for (x, y, _), spin in zip(offsets, ROTOR_SPINS)]
    return np.linalg.inv(np.array(columns).T)


def desaturation_gain(direction: ca.DM, command: ca.SX, low: float, high: float) -> ca.SX:
    """PX4's ``computeDesaturationGain``: the shift along ``direction`` that brings the
    rotors furthest below ``low`` and above ``high`` to their limits, added."""
    least, most = 0, 0
    for i in range(4):
        d, u = float(direction[i]), command[i]
        if math.isclose(d, 0.0, abs_tol=1e-12):
            continue
        gain = ca.if_else(u < low, (low - u) / d, ca.if_else(u > high, (high - u) / d, 0))
        least, most = ca.fmin(least, gain), ca.fmax(most, gain)
    return least + most


def desaturated(
    command: ca.SX, direction: ca.DM, reduce_only: bool = False, high: float = 1.0
) -> ca.SX:
    """PX4's ``desaturateActuators``: the shift, then half the shift still wanted;
    ``reduce_only``: along the thrust direction, only ever taking thrust off."""
    for share in (1.0, 0.5):
        gain = desaturation_gain(direction, command, 0.0, high)
        if reduce_only:
            gain = ca.fmin(gain, 0)
        command = command + share * gain * direction
    return command


def motor_commands_mixed(body: MulticopterSettings, wanted: ca.SX) -> ca.SX:
    """(4,) the rotors' commands (0..1 where they can be) for ``wanted`` [collective (N),
    roll, pitch, yaw (N m)], desaturated as PX4's mixer does with airmode off."""
    columns = ca.DM(allocation(body) / body.rotor_thrust_max_n)
    thrust, roll, pitch, yaw = (columns[:, i] for i in range(4))
    command = thrust * wanted[0] + roll * wanted[1] + pitch * wanted[2]
    command = desaturated(command, thrust, reduce_only=True)
    command = desaturated(command, roll)
    command = desaturated(command, pitch)
    command = command + yaw * wanted[3]
    command = desaturated(command, yaw, high=1.0 + YAW_MARGIN)
    return desaturated(command, thrust, reduce_only=True)
