"""The quadrotor's rigid body against closed-form answers: free fall with quadratic drag, the
air's force and moment on a hovering body, the motors' first-order lag, a wind carrying the
body, the signs of the rotors' moments, and the settings a body cannot have."""

from __future__ import annotations

import math
from dataclasses import replace

import casadi as ca
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
    STATE_SIZE,
    THRUSTS,
    VELOCITY,
    air_forces,
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


def test_free_fall_with_the_motors_off_follows_the_quadratic_drag_law(body):
    # rotors stopped: no rotor drag, the frame's c_Dz v^2 alone; v_t = sqrt(m g / c),
    # v(t) = -v_t tanh(g t / v_t), the drop (v_t^2 / g) ln cosh(g t / v_t)
    m, c = SETTINGS.mass_kg, SETTINGS.parasitic_drag_n_s2_m2[2]
    still = resting_state([0.0, 0.0, 100.0], SETTINGS)
    still[THRUSTS] = 0.0
    state = _fly(body, still, [0] * 4, 4)  # 2 s
    terminal = math.sqrt(m * G / c)
    drop = terminal**2 / G * math.log(math.cosh(G * 2.0 / terminal))
    assert state[POSITION][2] == pytest.approx(100.0 - drop, abs=1e-6)
    assert state[VELOCITY][2] == pytest.approx(-terminal * math.tanh(G * 2.0 / terminal), abs=1e-6)
    # and without drag, g t^2 / 2
    no_drag = RigidBody(replace(SETTINGS, parasitic_drag_n_s2_m2=(0.0, 0.0, 0.0)), STEP_S)
    assert _fly(no_drag, still, [0] * 4, 2)[2] == pytest.approx(100.0 - G * 1.0**2 / 2, abs=1e-9)


def test_the_airs_force_and_moment_on_a_hovering_body_are_rotorpys():
    # level, still, in a 5 m/s wind along x: each rotor's drag k_d omega W in its plane at its
    # hub (omega = sqrt(T / k_eta), T a quarter of the weight), the frame's c_Dx W^2; the hubs
    # rotor_height_m above the centre of mass pitch the body with the rotors' drag
    state_symbol, wind_symbol = ca.SX.sym("x", STATE_SIZE), ca.SX.sym("w", 3)
    air = ca.Function(
        "air", [state_symbol, wind_symbol], list(air_forces(SETTINGS, state_symbol, wind_symbol))
    )
    hovering = resting_state([0.0, 0.0, 10.0], SETTINGS)
    force, moment = (np.asarray(v).ravel() for v in air(hovering, [5.0, 0.0, 0.0]))
    s = SETTINGS
    omega = math.sqrt(s.mass_kg * G / 4 / s.rotor_thrust_coefficient)
    rotors = 4 * s.rotor_drag_coefficient * omega * 5.0
    assert force == pytest.approx(
        [rotors + s.parasitic_drag_n_s2_m2[0] * 25.0, 0.0, 0.0], rel=1e-12
    )
    assert moment == pytest.approx([0.0, s.rotor_height_m * rotors, 0.0], rel=1e-12, abs=1e-15)


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


def test_a_wind_carries_a_body_whose_drag_does_not_pitch_it():
    # rotors in the centre of mass' plane: the rotors' drag makes no moment, the body stays
    # level and is carried at the wind's speed (time constant m / (4 k_d omega) ~ 4 s)
    flat = replace(SETTINGS, rotor_height_m=0.0)
    body = RigidBody(flat, STEP_S)
    state = resting_state([0.0, 0.0, 50.0], flat)
    after = _fly(body, state, state[THRUSTS] / flat.rotor_thrust_max_n, 100, np.array([3.0, 0, 0]))
    assert after[VELOCITY] == pytest.approx([3.0, 0.0, 0.0], abs=1e-4)
    assert after[ATTITUDE] == pytest.approx([1.0, 0.0, 0.0, 0.0], abs=1e-12)


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
