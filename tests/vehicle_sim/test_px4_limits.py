"""The autopilot's limits as PX4 has them, flown: a steady wind held up to 90 % of the wind
the tilt limit can hold and not above it, the tilt at its limit before the speed, the mixer's
commands within [0, 1] in a 20 m move at full speed, and a gain set in flight taking effect."""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from mission.config.autopilot_settings import TUNED_FIELDS
from mission.config.multicopter_settings import STANDARD_GRAVITY as G
from mission.config.scenario import load_scenario
from vehicle_sim.dynamics.autopilot_loops import CONTROLLER_SIZE, motor_commands
from vehicle_sim.dynamics.closed_loop import ClosedLoop
from vehicle_sim.dynamics.rigid_body import (
    ATTITUDE,
    POSITION,
    STATE_SIZE,
    VELOCITY,
    air_forces,
    resting_state,
    rotation,
)

VEHICLE = load_scenario("along").vehicle
BODY, LOOPS = VEHICLE.multicopter, VEHICLE.autopilot
TICK_S = 0.1
HOME = np.array([0.0, 0.0, 10.0])


@pytest.fixture(scope="module")
def loop() -> ClosedLoop:
    return ClosedLoop(BODY, LOOPS, TICK_S)


def _start() -> np.ndarray:
    return np.concatenate([resting_state(HOME, BODY), np.zeros(CONTROLLER_SIZE)])


def _tilt_deg(q: np.ndarray) -> float:
    return math.degrees(math.acos(min(1.0, 1 - 2 * (q[1] ** 2 + q[2] ** 2))))


def _trim_tilt_deg(wind_m_s: float) -> float:
    """The tilt that holds the body still in a steady wind along x, from the body's own air
    forces (a fixed point of thrust and tilt: the rotors' drag depends on both)."""
    state, air = ca.SX.sym("x", STATE_SIZE), ca.SX.sym("w", 3)
    force = ca.Function(
        "f", [state, air], [rotation(state[ATTITUDE]) @ air_forces(BODY, state, air)[0]]
    )
    tilt, thrust = 0.0, BODY.mass_kg * G
    for _ in range(100):
        q = np.array([math.cos(tilt / 2), 0.0, -math.sin(tilt / 2), 0.0])  # leaning into it
        still = resting_state(HOME, BODY, q)
        still[-4:] = thrust / 4
        drag = np.asarray(force(still, [wind_m_s, 0.0, 0.0])).ravel()
        tilt = math.atan2(drag[0], BODY.mass_kg * G - drag[2])
        thrust = math.hypot(drag[0], BODY.mass_kg * G - drag[2])
    return math.degrees(tilt)


def _tilt_limit_wind() -> float:
    low, high = 1.0, 60.0
    for _ in range(40):
        middle = (low + high) / 2
        low, high = (middle, high) if _trim_tilt_deg(middle) < LOOPS.tilt_max_deg else (low, middle)
    return low


def _hover_in(loop, wind_m_s: float, seconds: float) -> np.ndarray:
    state, track = _start(), []
    for _ in range(round(seconds / TICK_S)):
        state, _ = loop.advance(state, HOME, np.zeros(3), 3.0, np.array([wind_m_s, 0.0, 0.0]))
        track.append(state[POSITION].copy())
    return np.array(track)


def test_a_steady_wind_is_held_below_the_tilt_limits_wind_and_blows_it_away_above(loop):
    limit = _tilt_limit_wind()  # 27.4 m/s with the defaults: RotorPy's drag, PX4's 45 degrees
    assert 20.0 < limit < 35.0
    held = _hover_in(loop, 0.9 * limit, 60.0)
    assert np.abs(held[-50:] - HOME).max() < 0.05  # back in place once the integral has it
    blown = _hover_in(loop, 1.1 * limit, 60.0)
    drift = blown[:, 0] - HOME[0]
    assert drift[-1] > 20.0 and drift[-1] > drift[-100] + 5.0  # still going downwind


def test_the_tilt_reaches_its_limit_before_the_speed_does(loop):
    state, tilts, speeds = _start(), [], []
    target = HOME + [60.0, 0.0, 0.0]
    for _ in range(100):
        state, _ = loop.advance(state, target, np.zeros(3), 12.0, np.zeros(3))
        tilts.append(_tilt_deg(state[ATTITUDE]))
        speeds.append(float(np.linalg.norm(state[VELOCITY][:2])))
    at_tilt = next(i for i, t in enumerate(tilts) if t > LOOPS.tilt_max_deg - 0.5)
    at_speed = next(i for i, s in enumerate(speeds) if s > 0.9 * LOOPS.horizontal_speed_max_m_s)
    assert at_tilt < at_speed
    assert max(tilts) < LOOPS.tilt_max_deg + 1.0  # and it is a limit
    # the configured one: MPC_TILTMAX_AIR at 30 degrees caps the same move there
    tuning = np.array(LOOPS.tuning())
    tuning[TUNED_FIELDS.index("tilt_max_deg")] = math.radians(30.0)
    state, tilts = _start(), []
    for _ in range(30):
        state, _ = loop.advance(state, target, np.zeros(3), 12.0, np.zeros(3), tuning=tuning)
        tilts.append(_tilt_deg(state[ATTITUDE]))
    assert 29.0 < max(tilts) < 31.0


def _commands_function():
    state, controller = ca.SX.sym("x", STATE_SIZE), ca.SX.sym("c", CONTROLLER_SIZE)
    sizes = (("t", 3), ("d", 3), ("s", 1), ("k", len(TUNED_FIELDS)), ("v", 3))
    inputs = [ca.SX.sym(n, k) for n, k in sizes]
    commands, _ = motor_commands(BODY, LOOPS, state, controller, tuple(inputs))
    return ca.Function("commands", [state, controller, *inputs], [commands])


def test_a_20_m_move_at_full_speed_keeps_every_rotor_within_its_range_and_the_attitude():
    every_substep = ClosedLoop(BODY, LOOPS, 1.0 / BODY.rate_hz)
    commands = _commands_function()
    state, target, tuning = _start(), HOME + [20.0, 0.0, 0.0], np.array(LOOPS.tuning())
    least, most, tilts = 1.0, 0.0, []
    for _ in range(round(15.0 * BODY.rate_hz)):
        wanted = commands(
            state[:STATE_SIZE], state[STATE_SIZE:], target, np.zeros(3), 12.0, tuning, np.zeros(3)
        )
        least, most = min(least, float(ca.mmin(wanted))), max(most, float(ca.mmax(wanted)))
        state, _ = every_substep.advance(state, target, np.zeros(3), 12.0, np.zeros(3))
        tilts.append(_tilt_deg(state[ATTITUDE]))
    # the mixer's own output, before the rotors clip it: desaturated, not clipped
    assert least >= -1e-9 and most <= 1 + 1e-9
    assert least < 0.05 and most > 0.95  # the move does reach the rotors' limits
    assert max(tilts) < LOOPS.tilt_max_deg + 2.0  # the attitude is kept
    assert np.abs(state[POSITION] - target).max() < 0.05


def test_a_gain_set_in_flight_changes_the_flight_without_a_new_compilation(loop):
    slow = np.array(LOOPS.tuning())
    slow[TUNED_FIELDS.index("horizontal_speed_max_m_s")] = 1.0
    state = _start()
    for _ in range(30):
        state, _ = loop.advance(
            state, HOME + [10.0, 0, 0], np.zeros(3), 12.0, np.zeros(3), tuning=slow
        )
    assert np.linalg.norm(state[VELOCITY][:2]) == pytest.approx(1.0, abs=0.02)
