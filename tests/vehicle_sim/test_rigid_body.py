"""The quadrotor's rigid body against closed-form answers: free fall with linear drag, the
motors' first-order lag, the terminal velocity of a constant tilt, the signs of the rotors'
moments, and the settings a body cannot have."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from mission.config.errors import FieldProblem
from mission.config.multicopter_settings import STANDARD_GRAVITY as G
from mission.config.scenario import load_scenario
from tests.vehicle_sim.rigid_body_alone import RigidBody
from vehicle_sim.dynamics.rigid_body import (
    ATTITUDE,
    POSITION,
    RATES,
    THRUSTS,
    VELOCITY,
    resting_state,
    substeps_of,
)

SETTINGS = load_scenario("along").vehicle.multicopter
STEP_S = 0.5
CALM = np.zeros(3)


@pytest.fixture(scope="module")
def body() -> RigidBody:
    return RigidBody(SETTINGS, STEP_S)


def _fly(body: RigidBody, state: np.ndarray, command, steps: int, wind=CALM) -> np.ndarray:
    for _ in range(steps):
        state = body.advance(state, np.asarray(command, dtype=float), wind)
    return state


def test_a_step_is_cut_into_equal_substeps_at_the_rate_or_faster(body):
    assert body.substeps == 125 and substeps_of(0.5, 300.0) == 150 and substeps_of(0.01, 250) == 3


def test_free_fall_with_the_motors_off_follows_the_drag_law(body):
    m, k = SETTINGS.mass_kg, SETTINGS.drag_n_per_m_s
    still = resting_state([0.0, 0.0, 100.0], SETTINGS)
    still[THRUSTS] = 0.0
    state = _fly(body, still, [0] * 4, 4)  # 2 s
    expected_drop = (m * G / k) * (2.0 - (m / k) * (1 - math.exp(-k * 2.0 / m)))
    assert state[POSITION][2] == pytest.approx(100.0 - expected_drop, abs=1e-6)
    assert state[VELOCITY][2] == pytest.approx(
        -(m * G / k) * (1 - math.exp(-k * 2.0 / m)), abs=1e-6
    )
    # and without drag, g t^2 / 2
    no_drag = RigidBody(replace(SETTINGS, drag_n_per_m_s=0.0), STEP_S)
    assert _fly(no_drag, still, [0] * 4, 2)[2] == pytest.approx(100.0 - G * 1.0**2 / 2, abs=1e-9)


def test_the_rotors_follow_their_command_with_a_first_order_lag(body):
    state = resting_state([0.0, 0.0, 100.0], SETTINGS)
    state[THRUSTS] = 0.0
    after = body.advance(state, np.full(4, 0.8), CALM)
    wanted = 0.8 * SETTINGS.rotor_thrust_max_n * (1 - math.exp(-STEP_S / SETTINGS.motor_tau_s))
    assert after[THRUSTS] == pytest.approx(np.full(4, wanted), abs=1e-9)


def test_hovering_thrust_holds_a_level_body_still(body):
    state = resting_state([3.0, -2.0, 10.0], SETTINGS)
    assert state[THRUSTS].sum() == pytest.approx(SETTINGS.mass_kg * G, rel=1e-12)
    after = _fly(body, state, state[THRUSTS] / SETTINGS.rotor_thrust_max_n, 10)
    assert np.abs(after[POSITION] - state[POSITION]).max() < 1e-9


def test_a_constant_tilt_reaches_the_terminal_velocity_of_its_drag(body):
    tilt = math.radians(20.0)
    q = np.array([math.cos(tilt / 2), math.sin(tilt / 2), 0.0, 0.0])  # roll right side down
    state = resting_state([0.0, 0.0, 50.0], SETTINGS, q)
    after = _fly(body, state, state[THRUSTS] / SETTINGS.rotor_thrust_max_n, 40)  # 20 s, 13 m/k
    terminal = SETTINGS.mass_kg * G * math.tan(tilt) / SETTINGS.drag_n_per_m_s
    assert after[VELOCITY] == pytest.approx([0.0, -terminal, 0.0], abs=1e-5)
    assert after[ATTITUDE] == pytest.approx(q, abs=1e-9)  # equal thrusts: no moment


def test_a_wind_is_felt_through_the_drag(body):
    state = resting_state([0.0, 0.0, 50.0], SETTINGS)
    after = _fly(
        body, state, state[THRUSTS] / SETTINGS.rotor_thrust_max_n, 40, np.array([3.0, 0, 0])
    )
    assert after[VELOCITY] == pytest.approx(
        [3.0, 0.0, 0.0], abs=1e-5
    )  # carried at the wind's speed


@pytest.mark.parametrize(
    ("more_on", "axis", "sign"),
    [
        ((0, 1), 0, 1.0),  # the left rotors: roll, right side down (+x)
        ((1, 2), 1, 1.0),  # the rear rotors: nose down (+y: the FLU pitch axis points left)
        ((1, 3), 2, -1.0),  # the counter-clockwise ones: their reaction turns the body clockwise
    ],
)
def test_the_rotors_moments_turn_the_body_the_right_way(body, more_on, axis, sign):
    state = resting_state([0.0, 0.0, 50.0], SETTINGS)
    command = state[THRUSTS] / SETTINGS.rotor_thrust_max_n
    command[list(more_on)] *= 1.02
    short = RigidBody(SETTINGS, 0.02)
    rates = short.advance(state, command, CALM)[RATES]
    assert (
        np.sign(rates[axis]) == sign
        and abs(rates[axis]) > 10 * np.abs(np.delete(rates, axis)).max()
    )


@pytest.mark.parametrize(
    ("field", "value", "problem"),
    [
        ("mass_kg", -1.5, "positive"),
        ("inertia_kg_m2", (0.0375, 0.0, 0.045), "singular"),
        ("inertia_kg_m2", (0.01, 0.01, 0.05), "triangle"),
        ("rate_hz", 40.0, "at least 50"),
        ("rotor_thrust_max_n", 3.0, "could not hover"),
    ],
)
def test_a_body_that_cannot_be_is_refused(field, value, problem):
    with pytest.raises(FieldProblem, match=problem):
        replace(SETTINGS, **{field: value})
