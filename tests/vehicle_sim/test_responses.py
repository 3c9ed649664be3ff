"""The quadrotor's step and gust responses beside the linear design of PX4's cascade with the
same gains (``mission vehicle``): the model follows the design, and the design its own
closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mission.config.scenario import load_scenario
from vehicle_sim.dynamics.closed_loop import ClosedLoop
from vehicle_sim.dynamics.responses import (
    design_response,
    gust_response,
    settling_s,
    step_response,
)

VEHICLE = load_scenario("along").vehicle


@pytest.fixture(scope="module")
def loop() -> ClosedLoop:
    return ClosedLoop(VEHICLE.multicopter, VEHICLE.autopilot, 0.02)


def test_the_model_follows_pxs_linear_design_in_a_step_and_a_gust(loop):
    step, gust = step_response(loop), gust_response(loop)
    # what separates them is what the design leaves out: attitude, motors, limits, drag's curve
    assert step.model_m.max() - 1 == pytest.approx(step.design_m.max() - 1, abs=0.015)
    settle = [settling_s(step.times_s, v, 1.0, 0.02) for v in (step.model_m, step.design_m)]
    assert settle[0] == pytest.approx(settle[1], abs=0.5) and settle[0] < 6.0
    assert gust.model_m.max() == pytest.approx(gust.design_m.max(), rel=0.25)
    assert abs(gust.model_m[-1]) < 0.02 and abs(gust.design_m[-1]) < 0.02  # the integral


def test_the_design_without_integral_or_derivative_is_its_closed_form():
    # x' = v, v' = kv (kp (1 - x) - v) - c v: roots of s^2 + (kv + c) s + kv kp
    loops = VEHICLE.autopilot
    from dataclasses import replace

    plain = replace(loops, velocity_integral_gain_per_s2=0.0, velocity_derivative_gain=0.0)
    c, kp, kv = 0.3, plain.position_gain_per_s, plain.velocity_gain_per_s
    times = np.array([0.5, 1.0, 2.0, 4.0])
    found = design_response(plain, c, times, 1.0, lambda t: 0.0)
    roots = np.roots([1.0, kv + c, kv * kp])
    r1, r2 = roots
    expected = 1 + (r2 * np.exp(r1 * times) - r1 * np.exp(r2 * times)) / (r1 - r2)
    assert found == pytest.approx(np.real(expected), abs=2e-3)  # Euler at 1 ms


def test_settling_is_when_the_values_stay_within_the_band():
    times = np.array([1.0, 2.0, 3.0, 4.0])
    assert settling_s(times, np.array([0.0, 0.9, 1.05, 1.0]), 1.0, 0.02) == 4.0
    assert settling_s(times, np.array([1.0, 1.0, 1.0, 1.0]), 1.0, 0.02) == 0.0
    assert settling_s(times, np.array([1.0, 1.0, 1.0, 0.5]), 1.0, 0.02) == math.inf
