"""Whether a multicopter's settings can be flown and integrated: checked up front,
so that a body or loop the model cannot integrate is refused on one line, not found out by
every vehicle dying at its first step.

- The integration step h = 1 / ``rate_hz`` (at most :data:`MAX_RATE_HZ`: a step of substeps
  is computed whole) is at most half of the body's fastest time constants: the motors' lag,
  mass over the rotors' drag at hover, the least moment of inertia over the rotational
  damping (a classical
  Runge-Kutta step is stable to |lambda h| ~ 2.8; two steps a time constant keeps it accurate).
- The rate loop, a gain K on the rate error through the motors' first-order lag tau, is the
  second-order loop s^2 tau + s + K: its natural frequency sqrt(K / tau) at most
  :data:`MAX_LOOP_FREQUENCY_STEPS` / h (it runs once a substep, its command held) and its
  damping 1 / (2 sqrt(K tau)) at least :data:`MIN_RATE_LOOP_DAMPING`.
- The cascade runs each loop at least :data:`MIN_CASCADE_RATIO` times slower than the one
  inside it: velocity, attitude, rate (closer, the loops couple: 30/60/99 per s passes every
  check above and crashes); the position loop at least :data:`MIN_POSITION_RATIO` times
  slower than the velocity loop (PX4's defaults, 0.95 and 1.8: its velocity loop's integral
  and derivative let the two sit closer).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

from mission.config.autopilot_settings import PX4_PARAMETERS, AutopilotSettings
from mission.config.checks import require
from mission.config.errors import FieldProblem
from mission.config.multicopter_settings import STANDARD_GRAVITY, MulticopterSettings

MAX_RATE_HZ = 2000.0
STEPS_PER_TIME_CONSTANT = 2.0
MAX_LOOP_FREQUENCY_STEPS = 0.5  # the rate loop's natural frequency times h
MIN_RATE_LOOP_DAMPING = 0.2
MAX_THRUST_TO_WEIGHT = 10.0
MIN_CASCADE_RATIO = 2.5  # the defaults: 4.4, 3.1 (a rule of thumb is 3-5)
MIN_POSITION_RATIO = 1.5  # the defaults: 1.9 (PX4's)


def check_flyable(body: MulticopterSettings, loops: AutopilotSettings) -> None:
    """FieldProblem naming ``multicopter.*`` or ``autopilot.*`` where they cannot be flown."""
    require(
        body.rate_hz <= MAX_RATE_HZ,
        "multicopter.rate_hz",
        f"must be at most {MAX_RATE_HZ:g} Hz, got {body.rate_hz:g}",
    )
    h = 1.0 / body.rate_hz
    constants = [("motor_tau_s", "the motors' lag", body.motor_tau_s)]
    hover_speed = math.sqrt(body.mass_kg * STANDARD_GRAVITY / 4 / body.rotor_thrust_coefficient)
    drag = 4 * hover_speed * body.rotor_drag_coefficient
    if drag > 0:
        constants.append(("mass_kg", "mass over the rotors' drag", body.mass_kg / drag))
    if body.rotational_damping_n_m_per_rad_s > 0:
        least = min(body.inertia_kg_m2) / body.rotational_damping_n_m_per_rad_s
        constants.append(("inertia_kg_m2", "inertia over rotational damping", least))
    for name, what, tau in constants:
        require(
            tau >= STEPS_PER_TIME_CONSTANT * h,
            f"multicopter.{name}",
            f"makes {what} {tau:.3g} s, shorter than {STEPS_PER_TIME_CONSTANT:g} integration "
            f"steps ({STEPS_PER_TIME_CONSTANT * h:.3g} s at rate_hz {body.rate_hz:g}): the "
            "model cannot integrate it",
        )
    gain, lag = loops.rate_gain_per_s, body.motor_tau_s
    frequency, damping = math.sqrt(gain / lag), 1.0 / (2.0 * math.sqrt(gain * lag))
    require(
        frequency * h <= MAX_LOOP_FREQUENCY_STEPS,
        "autopilot.rate_gain_per_s",
        f"{gain:g} makes the rate loop ring at {frequency:.3g} rad/s, too fast for its "
        f"{body.rate_hz:g} Hz (at most {MAX_LOOP_FREQUENCY_STEPS * body.rate_hz:.3g})",
    )
    require(
        damping >= MIN_RATE_LOOP_DAMPING,
        "autopilot.rate_gain_per_s",
        f"{gain:g} with the motors' {lag:g} s lag damps the rate loop {damping:.2f} "
        f"(at least {MIN_RATE_LOOP_DAMPING:g}: K tau at most "
        f"{1 / (4 * MIN_RATE_LOOP_DAMPING**2):g})",
    )
    _check_rotors(body)
    cascade = ("position", "velocity", "attitude", "rate")
    for outer, inner in itertools.pairwise(cascade):
        least = MIN_POSITION_RATIO if outer == "position" else MIN_CASCADE_RATIO
        slow = getattr(loops, f"{outer}_gain_per_s")
        fast = getattr(loops, f"{inner}_gain_per_s")
        require(
            least * slow <= fast,
            f"autopilot.{outer}_gain_per_s",
            f"{slow:g} must be below {inner}_gain_per_s ({fast:g}) by a factor of at least "
            f"{least:g}: a loop too close to the one it commands couples with it",
        )


def _check_rotors(body: MulticopterSettings) -> None:
    """The rotors' thrust and torque within what a quadrotor has."""
    hover = body.mass_kg * STANDARD_GRAVITY / 4
    require(
        body.rotor_thrust_max_n <= MAX_THRUST_TO_WEIGHT * hover,
        "multicopter.rotor_thrust_max_n",
        f"must be at most {MAX_THRUST_TO_WEIGHT:g} times a quarter of the weight "
        f"({hover:.2f} N; a racing quadrotor's thrust-to-weight)",
    )
    require(
        body.rotor_torque_max_n_m <= body.rotor_thrust_max_n * body.lever_m,
        "multicopter.rotor_torque_max_n_m",
        "must be at most rotor_thrust_max_n x lever_m (a propeller's drag torque is a few per "
        "cent of its thrust's moment)",
    )


def check_fault_tunings(faults: Sequence[Any], vehicle: Any) -> None:
    """A fault that sets a flying vehicle's PX4 gain leaves loops it can fly (each fault
    against the scenario's other settings); FieldProblem naming ``faults[i].value``."""
    if vehicle.dynamics != "multicopter":
        return
    for i, fault in enumerate(faults):
        field = PX4_PARAMETERS.get(str(fault.param))
        if field is None or fault.value is None:
            continue
        try:
            check_flyable(vehicle.multicopter, replace(vehicle.autopilot, **{field: fault.value}))
        except FieldProblem as problem:
            raise FieldProblem(f"faults[{i}].value", problem.problem) from None
