"""The rigid body integrated over a whole step on its own, its rotors' commands held (no
autopilot): what the tests fly it with against closed-form answers. The vehicle flies the
same substep folded with its autopilot (:mod:`vehicle_sim.dynamics.closed_loop`)."""

from __future__ import annotations

import casadi as ca
import numpy as np

from mission.config.multicopter_settings import MulticopterSettings
from vehicle_sim.dynamics.rigid_body import (
    OPEN_AIR,
    STATE_SIZE,
    SURFACES_SIZE,
    runge_kutta_substep,
    substeps_of,
)


class RigidBody:
    """The model's step for one settings and step length: :meth:`advance` integrates it."""

    def __init__(self, settings: MulticopterSettings, step_s: float) -> None:
        self.settings = settings
        self.step_s = step_s
        self.substeps = substeps_of(step_s, settings.rate_hz)
        h = step_s / self.substeps
        state, command, wind = ca.SX.sym("x", STATE_SIZE), ca.SX.sym("u", 4), ca.SX.sym("w", 3)
        surfaces = ca.SX.sym("h", SURFACES_SIZE)
        after = runge_kutta_substep(settings, state, command, wind, surfaces, h)
        substep = ca.Function("substep", [state, command, wind, surfaces], [after])
        self._step = substep.fold(self.substeps)

    def advance(
        self,
        state: np.ndarray,
        command: np.ndarray,
        wind: np.ndarray,
        surfaces: np.ndarray = OPEN_AIR,
    ) -> np.ndarray:
        """The state one step later, ``command``, ``wind`` and ``surfaces`` (the heights
        above, then below, each rotor: :data:`OPEN_AIR` by default) held over it."""
        count = self.substeps
        held = [(command, 4), (wind, 3), (surfaces, SURFACES_SIZE)]
        result = self._step(
            np.asarray(state, dtype=float),
            *(np.repeat(np.asarray(v, dtype=float).reshape(n, 1), count, axis=1) for v, n in held),
        )
        return np.asarray(result, dtype=float).reshape(STATE_SIZE)
