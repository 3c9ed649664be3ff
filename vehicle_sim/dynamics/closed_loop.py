"""The rigid body flown by its autopilot over one simulation step (docs/model.md, "A
multicopter's dynamics"): at every substep the position controller
(:mod:`~vehicle_sim.dynamics.autopilot_loops`) computes the rotors' commands, held while the
body (:mod:`~vehicle_sim.dynamics.rigid_body`) is integrated over the substep (a classical
Runge-Kutta step) and the controller's integral by Euler, as a flight controller's loop runs
at a fixed rate. One casadi Function does a whole step, compiled with the system C
compiler and cached as the support MPC is; the same inputs give the same state bit for bit.

State (23): the body's 17, then the controller's (6: the velocity error's integral and the
low-passed velocity). A step also gives the body's position and attitude after every few
substeps: the path contact detection follows.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from mission.codegen.casadi_buffer import BufferedFunction
from mission.codegen.casadi_cache import compiled_function
from mission.codegen.news import Compiling
from mission.config.autopilot_settings import TUNED_FIELDS, AutopilotSettings
from mission.config.multicopter_settings import MulticopterSettings
from vehicle_sim.dynamics.autopilot_loops import CONTROLLER_SIZE, motor_commands
from vehicle_sim.dynamics.rigid_body import (
    ATTITUDE,
    OPEN_AIR,
    POSITION,
    STATE_SIZE,
    SURFACES_SIZE,
    runge_kutta_substep,
    substeps_of,
)

DYNAMICS = Compiling("vehicle", "its flight dynamics", "vehicle_flight")
FLIGHT_STATE_SIZE = STATE_SIZE + CONTROLLER_SIZE
CONTROLLER = slice(STATE_SIZE, FLIGHT_STATE_SIZE)
INTEGRAL = slice(STATE_SIZE, STATE_SIZE + 3)
SMOOTHED_VELOCITY = slice(STATE_SIZE + 3, FLIGHT_STATE_SIZE)
TUNING_SIZE = len(TUNED_FIELDS)
POSE_SIZE = 7  # a path point: position (3), attitude quaternion (4)
OUTPUTS = ("final", "path")
PATH_INTERVAL_S = 0.02  # the path's points at most this far apart in time (3 cm at 1.5 m/s)


def path_stride(substeps: int, h: float) -> int:
    """The most substeps between two of the path's points: a divisor of ``substeps`` at most
    :data:`PATH_INTERVAL_S` long (1: every substep)."""
    fitting = [n for n in range(1, substeps + 1) if substeps % n == 0 and n * h <= PATH_INTERVAL_S]
    return max(fitting, default=1)


class ClosedLoop:
    """One step of the flown body: :meth:`advance` (state, target, belief offset, speed limit,
    wind, surfaces, tuning) -> the state a step later and the poses on the way."""

    def __init__(
        self,
        body: MulticopterSettings,
        loops: AutopilotSettings,
        step_s: float,
        compiled: bool = True,
    ) -> None:
        """``compiled``: with the system C compiler (cached once per machine and settings),
        else casadi's interpreter (the same states, slower)."""
        self.body, self.loops, self.step_s = body, loops, step_s
        self.tuning = np.array(loops.tuning())
        self.substeps = substeps_of(step_s, body.rate_hz)
        h = step_s / self.substeps
        flight = ca.SX.sym("x", FLIGHT_STATE_SIZE)
        target, offset, wind = ca.SX.sym("t", 3), ca.SX.sym("d", 3), ca.SX.sym("w", 3)
        speed, surfaces = ca.SX.sym("s"), ca.SX.sym("h", SURFACES_SIZE)
        tuning, feedforward = ca.SX.sym("k", TUNING_SIZE), ca.SX.sym("v", 3)
        elapsed = ca.SX.sym("e")  # since the step began: the target moves on at the feed-forward
        state, controller = flight[:STATE_SIZE], flight[CONTROLLER]
        moving = (target + feedforward * elapsed, offset, speed, tuning, feedforward)
        command, controller_rate = motor_commands(body, loops, state, controller, moving)
        after = runge_kutta_substep(body, state, command, wind, surfaces, h)
        after = ca.vertcat(after, controller + h * controller_rate)
        inputs = [flight, target, offset, speed, tuning, feedforward, surfaces, wind, elapsed]
        substep = ca.Function("flight", inputs, [after])
        # the state after every few substeps (at most PATH_INTERVAL_S apart): the path
        stride = path_stride(self.substeps, h)
        stretch = substep.fold(stride) if stride > 1 else substep
        stretches = stretch.mapaccum(self.substeps // stride)
        sizes = (("t", 3), ("d", 3), ("s", 1), ("k", TUNING_SIZE), ("v", 3))
        held = [ca.MX.sym(name, size) for name, size in (*sizes, ("h", SURFACES_SIZE))]
        gusty = ca.MX.sym("w", 3, self.substeps)  # the wind at each substep
        start = ca.MX.sym("x", FLIGHT_STATE_SIZE)
        clock = ca.DM(np.arange(self.substeps) * h).T  # each substep's start in the step
        repeated = (ca.repmat(value, 1, self.substeps) for value in held)
        states = stretches(start, *repeated, gusty, clock)
        final = states[:, -1]
        path = ca.vertcat(states[POSITION, :], states[ATTITUDE, :])
        names = ["x", *(name for name, _ in sizes), "h", "w"]
        step = ca.Function("flight_step", [start, *held, gusty], [final, path], names, OUTPUTS)
        # called on arrays it keeps: converting its eight arguments each call cost 0.1 ms, about
        # as much as the step itself
        self._step = BufferedFunction(compiled_function(step, DYNAMICS, compiled), OUTPUTS)

    def advance(
        self,
        state: np.ndarray,
        target: np.ndarray,
        belief_offset: np.ndarray,
        speed_limit_m_s: float,
        wind: np.ndarray,
        surfaces: np.ndarray = OPEN_AIR,
        tuning: np.ndarray | None = None,
        feedforward: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """(the state a step later, (n, 7) the position and attitude after every few
        substeps, the last one the step's end: :func:`path_stride`); ``wind`` (3,) held over
        the step, or (substeps, 3) one vector a substep; ``surfaces`` the heights above, then
        below, each rotor (:data:`~vehicle_sim.dynamics.rigid_body.OPEN_AIR`: none near);
        ``tuning`` the loops' tunable values (None: the settings'); ``feedforward`` the
        setpoint's velocity (None: none), along which the target moves over the step."""
        wind = np.asarray(wind, dtype=float)
        winds = np.tile(wind, self.substeps) if wind.ndim == 1 else wind.ravel()
        tuning = self.tuning if tuning is None else tuning
        feedforward = 0.0 if feedforward is None else feedforward
        out = self._step(
            x=state,
            t=target,
            d=belief_offset,
            s=speed_limit_m_s,
            k=tuning,
            v=feedforward,
            h=surfaces,
            w=winds,  # (substeps, 3) row by row: the (3, substeps) input column by column
        )
        return out["final"], out["path"].reshape(-1, POSE_SIZE)
