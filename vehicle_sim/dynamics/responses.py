"""A flown quadrotor's step and gust responses, beside the linear design of PX4's cascade
with the same gains (docs/model.md, "A multicopter's dynamics"; ``mission vehicle``).

**The model's**: the closed loop (:class:`~vehicle_sim.dynamics.closed_loop.ClosedLoop`)
flown from rest in still air, hovering, every ``tick`` seconds: a position step along x; or,
holding, a steady wind along x from 1 s on.

**The design's**: the same position P and velocity PID (the D on the velocity's rate,
low-passed) acting on a point mass whose acceleration is the one asked for (the attitude and
the rotors instant, no limits), with the body's drag linearised at hover: the rotors'
4 k_d omega_hover per kg (the frame's quadratic drag is nil at rest). What separates the two
curves is what the design leaves out: the attitude and rate loops, the motors' lag, the tilt
and thrust limits, the drag's non-linearity.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mission.config.autopilot_settings import AutopilotSettings
from mission.config.multicopter_settings import STANDARD_GRAVITY, MulticopterSettings
from vehicle_sim.dynamics.autopilot_loops import CONTROLLER_SIZE
from vehicle_sim.dynamics.closed_loop import ClosedLoop
from vehicle_sim.dynamics.rigid_body import ATTITUDE, POSITION, resting_state

HOME = np.array([0.0, 0.0, 10.0])
DESIGN_DT_S = 0.001
GUST_START_S = 1.0


@dataclass(frozen=True)
class Response:
    """A response's samples: times (s), the model's and the design's displacement along x
    (m), and the model's tilt (degrees)."""

    times_s: np.ndarray
    model_m: np.ndarray
    design_m: np.ndarray
    tilt_deg: np.ndarray


def hover_drag_per_kg(body: MulticopterSettings) -> float:
    """The rotors' drag per m/s of air, per kg, hovering: 4 k_d omega_hover / m."""
    omega = math.sqrt(body.mass_kg * STANDARD_GRAVITY / 4 / body.rotor_thrust_coefficient)
    return 4 * body.rotor_drag_coefficient * omega / body.mass_kg


def design_response(
    loops: AutopilotSettings, drag_per_kg: float, times_s: np.ndarray, target_m: float, wind_m_s
) -> np.ndarray:
    """The linear design's displacement at ``times_s``: toward ``target_m`` from 0, in a wind
    of ``wind_m_s`` (a function of time) along x."""
    kp, kv = loops.position_gain_per_s, loops.velocity_gain_per_s
    ki, kd = loops.velocity_integral_gain_per_s2, loops.velocity_derivative_gain
    cutoff = 2 * math.pi * loops.velocity_derivative_cutoff_hz
    x = v = integral = smoothed = 0.0
    out, t, dt = [], 0.0, DESIGN_DT_S
    for until in times_s:
        while t < until - 1e-12:
            error = kp * (target_m - x) - v
            rate = cutoff * (v - smoothed)
            asked = kv * error + integral - kd * rate
            accel = asked - drag_per_kg * (v - wind_m_s(t))
            x, v = x + v * dt, v + accel * dt
            integral += ki * error * dt
            smoothed += rate * dt
            t += dt
        out.append(x)
    return np.array(out)


def _fly(loop: ClosedLoop, target: np.ndarray, seconds: float, wind_m_s) -> tuple:
    state = np.concatenate([resting_state(HOME, loop.body), np.zeros(CONTROLLER_SIZE)])
    times, xs, tilts = [], [], []
    for k in range(round(seconds / loop.step_s)):
        wind = np.array([wind_m_s(k * loop.step_s), 0.0, 0.0])
        state, _ = loop.advance(state, target, np.zeros(3), 100.0, wind)
        q = state[ATTITUDE]
        times.append((k + 1) * loop.step_s)
        xs.append(state[POSITION][0] - HOME[0])
        tilts.append(math.degrees(math.acos(min(1.0, 1 - 2 * (q[1] ** 2 + q[2] ** 2)))))
    return np.array(times), np.array(xs), np.array(tilts)


def step_response(loop: ClosedLoop, step_m: float = 1.0, seconds: float = 10.0) -> Response:
    """A position step of ``step_m`` along x, from rest in still air."""
    times, xs, tilts = _fly(loop, HOME + [step_m, 0.0, 0.0], seconds, lambda t: 0.0)
    design = design_response(loop.loops, hover_drag_per_kg(loop.body), times, step_m, lambda t: 0.0)
    return Response(times, xs, design, tilts)


def gust_response(loop: ClosedLoop, wind_m_s: float = 3.0, seconds: float = 20.0) -> Response:
    """Holding in still air, a steady wind of ``wind_m_s`` along x from 1 s on."""

    def wind(t: float) -> float:
        return wind_m_s if t >= GUST_START_S else 0.0

    times, xs, tilts = _fly(loop, HOME, seconds, wind)
    design = design_response(loop.loops, hover_drag_per_kg(loop.body), times, 0.0, wind)
    return Response(times, xs, design, tilts)


def settling_s(times: np.ndarray, values: np.ndarray, final: float, band_m: float) -> float:
    """The time after which ``values`` stay within ``band_m`` of ``final`` (inf: they do not
    by the end; 0: they never leave it)."""
    outside = np.flatnonzero(np.abs(values - final) > band_m)
    if not len(outside):
        return 0.0
    if outside[-1] + 1 >= len(times):
        return math.inf
    return float(times[outside[-1] + 1])
