"""PX4's velocity loop and thrust limits against hand computations: hover, the tilt limit,
the vertical priority's margin, and both anti-windups."""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from mission.config.multicopter_settings import STANDARD_GRAVITY as G
from vehicle_sim.dynamics.px4_thrust import thrust_setpoint

HOVER = 0.5
GAINS = (1.8, 4.0, 0.4, 2.0)  # PX4's MPC_XY_VEL_P_ACC, MPC_Z_VEL_P_ACC, ..._I_ACC
TILT = math.radians(45.0)
LIMITS = (TILT, 0.12, 1.0, 0.3)  # MPC_TILTMAX_AIR, MPC_THR_MIN, MPC_THR_MAX, MPC_THR_XY_MARG


def _evaluate(error, integral=(0.0, 0.0, 0.0), damping=(0.0, 0.0, 0.0)):
    e, i, d = ca.SX.sym("e", 3), ca.SX.sym("i", 3), ca.SX.sym("d", 3)
    thrust, rate = thrust_setpoint(e, i, d, HOVER, GAINS, LIMITS)
    function = ca.Function("f", [e, i, d], [thrust, rate])
    arrays = (np.array(v, float) for v in (error, integral, damping))
    thrust, rate = function(*arrays)
    return np.array(thrust).ravel(), np.array(rate).ravel()


def test_no_error_is_hover_thrust_and_nothing_to_integrate():
    thrust, rate = _evaluate([0.0, 0.0, 0.0])
    assert thrust == pytest.approx([0.0, 0.0, HOVER]) and rate == pytest.approx([0, 0, 0])


def test_a_large_horizontal_error_leans_to_the_tilt_limit_and_holds_altitude():
    thrust, _ = _evaluate([20.0, 0.0, 0.0])
    assert math.atan2(thrust[0], thrust[2]) == pytest.approx(TILT)
    assert thrust[2] == pytest.approx(HOVER)  # the vertical thrust is kept
    assert thrust[0] == pytest.approx(HOVER * math.tan(TILT))  # a = g tan(tilt) sideways


def test_a_small_error_is_the_acceleration_asked_for():
    thrust, rate = _evaluate([0.5, -0.2, 0.1])
    a = np.array([1.8 * 0.5, 1.8 * -0.2, 4.0 * 0.1])
    vertical = HOVER * (1 + a[2] / G)
    assert thrust == pytest.approx([a[0] / G * vertical, a[1] / G * vertical, vertical])
    assert rate == pytest.approx([0.4 * 0.5, 0.4 * -0.2, 2.0 * 0.1])


def test_the_vertical_keeps_all_but_the_margin_and_the_horizontal_gets_the_rest():
    thrust, rate = _evaluate([20.0, 0.0, 5.0])  # up hard and sideways: saturated
    assert thrust[2] == pytest.approx(math.sqrt(1.0 - 0.3**2))
    assert np.linalg.norm(thrust) == pytest.approx(1.0)  # the rest to the horizontal
    assert rate[2] == 0.0  # at the maximum, asking for more up: not integrated
    a_wanted = 1.8 * 20.0
    produced = thrust[0] * G / thrust[2]  # the tilt it makes: g tan(tilt)
    assert rate[0] == pytest.approx(0.4 * (20.0 - 2.0 / 1.8 * (a_wanted - produced)))


def test_a_descent_below_the_minimum_thrust_stops_integrating_down():
    thrust, rate = _evaluate([0.0, 0.0, -10.0])
    assert thrust[2] == pytest.approx(0.12) and rate[2] == 0.0


def test_the_derivative_term_takes_its_acceleration_off_the_setpoint():
    # PX4: a_sp = Kp e + integral - Kd dv/dt; a 0.1 m/s error against a 0.2 m/s2 damping term
    thrust, _ = _evaluate([0.1, 0.0, 0.0], damping=[0.2, 0.0, 0.0])
    assert thrust[0] == pytest.approx(HOVER * (1.8 * 0.1 - 0.2) / G, rel=1e-6)
