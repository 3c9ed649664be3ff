"""A vehicle's motion as a flying quadrotor (``vehicle.dynamics: multicopter``; docs/model.md,
"A multicopter's dynamics"): the rigid body of :mod:`~vehicle_sim.dynamics.rigid_body` flown by
the position controller of :mod:`~vehicle_sim.dynamics.autopilot_loops` over each step, with
the interface of :class:`~vehicle_sim.dynamics.kinematics.Kinematics` (truth, belief, target,
velocity).

The autopilot steers from the position it believes. Its belief is the truth plus an offset that
each VISION_POSITION_ESTIMATE sets (the estimate's error, as the kinematic model keeps it);
between estimates the belief follows the vehicle by its navigation filter's velocity, the true
one plus a bias (per run and axis) and noise (per step): the offset drifts.
``vehicle.tracking_noise_m`` still kicks the true position each step, as in the kinematic
model. The wind (:mod:`mission.world.wind`: the run's one turbulence field, the same in every
vehicle) is sampled at the vehicle's true position at the start of each step, one vector a
substep at the simulated time; so are the surfaces above and below each rotor (the ceiling and
ground effects: :mod:`mission.world.surfaces`), held over the step.

It starts hovering in trim: its velocity loop's integral already holds off the mean wind's
drag where it is, as that of a vehicle that took off in the wind and climbed there would.
The loops' tunable values (PX4's MPC_* parameters) can change between steps (:meth:`tune`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from mission.config.autopilot_settings import AutopilotSettings
from mission.config.errors import FieldProblem
from mission.config.flight_checks import check_flyable
from mission.config.planner_vehicle_settings import VehicleSettings
from mission.config.settings import BoxPrimitive
from mission.config.wind_settings import WindSettings
from mission.world.frames import quaternion_matrix
from mission.world.surfaces import VerticalSurfaces
from mission.world.wind import VehicleWind
from vehicle_sim.dynamics.autopilot_loops import CONTROLLER_SIZE
from vehicle_sim.dynamics.closed_loop import INTEGRAL, ClosedLoop
from vehicle_sim.dynamics.rigid_body import (
    ATTITUDE,
    OPEN_AIR,
    POSITION,
    RATES,
    VELOCITY,
    hover_drag,
    resting_state,
)

CALM = np.zeros(3)


class Multicopter:
    """True and believed position of one flying quadrotor, its position target and state."""

    def __init__(
        self,
        loop: ClosedLoop,
        home: np.ndarray,
        wind: VehicleWind | None = None,
        drift_rng: np.random.Generator | None = None,
        surfaces: VerticalSurfaces | None = None,
    ) -> None:
        self.loop = loop
        self.wind = wind  # None: still air
        # None, or no proximity effect in the body: nothing near changes the thrust
        self.surfaces = surfaces if loop.body.proximity_effects else None
        self.rotors = loop.body.rotor_hubs()
        loops = loop.loops
        self.drift_rng = drift_rng  # None: the belief moves with the truth exactly
        self.velocity_bias = (
            np.zeros(3) if drift_rng is None else drift_rng.normal(0.0, loops.velocity_bias_m_s, 3)
        )
        self.state = self._resting(home)
        if wind is not None:
            self.state[INTEGRAL] = -hover_drag(loop.body, wind.mean_at(home)) / loop.body.mass_kg
        self.settings: AutopilotSettings = loop.loops
        self.tuning = loop.tuning.copy()
        self.offset = np.zeros(3)  # believed - true position
        self.target: np.ndarray | None = None
        self.target_velocity: np.ndarray | None = None  # a setpoint's: the target moves on
        self.path = self._pose()[None]  # true poses (position, attitude) over the last step

    def _resting(self, position: np.ndarray) -> np.ndarray:
        return np.concatenate([resting_state(position, self.loop.body), np.zeros(CONTROLLER_SIZE)])

    def _pose(self) -> np.ndarray:
        return np.concatenate([self.state[POSITION], self.state[ATTITUDE]])

    def tuning_problem(self, field: str, value: float) -> str | None:
        """Why the loops could not fly with ``field`` (an :class:`AutopilotSettings` field) at
        ``value``, the rest as they are: the settings' own checks and the flight checks a
        scenario's pass (None: they could)."""
        try:
            check_flyable(self.loop.body, replace(self.settings, **{field: value}))
        except FieldProblem as problem:
            return problem.problem
        return None

    def tune(self, field: str, value: float) -> None:
        """Set one of the loops' tunable values from the next step on (one
        :meth:`tuning_problem` found none for)."""
        self.settings = replace(self.settings, **{field: value})
        self.tuning = np.array(self.settings.tuning())

    @classmethod
    def at(
        cls,
        home: np.ndarray,
        vehicle: VehicleSettings,
        step_s: float,
        wind: WindSettings | None = None,
        boxes: list[BoxPrimitive] | None = None,
        wind_seed: int | None = None,
        drift_rng: np.random.Generator | None = None,
        surfaces: VerticalSurfaces | None = None,
    ) -> Multicopter:
        """A quadrotor hovering at ``home`` that knows where it is, in ``wind`` around the
        structure's ``boxes`` (its gusts the field of the run's ``wind_seed``), or in still
        air; its belief
        drifting between estimates by the filter's velocity error (drawn from ``drift_rng``),
        or not at all; its rotors' thrust changed by the ``surfaces`` near them, or by
        none."""
        loop = ClosedLoop(vehicle.multicopter, vehicle.autopilot, step_s)
        home = np.asarray(home, dtype=float).reshape(3)
        weather = None
        if wind is not None and wind_seed is not None:
            weather = VehicleWind.of(wind, boxes or [], step_s / loop.substeps, wind_seed)
        return cls(loop, home, weather, drift_rng, surfaces)

    def set_wind(self, settings: WindSettings, now_s: float | None = None) -> None:
        """The wind from now on: the same as before, or a new one (the same run's field; still
        air without one), its clock at the simulated time ``now_s`` (None: where it was)."""
        if self.wind is None:
            return
        if settings != self.wind.field.settings:
            self.wind = self.wind.blowing(settings)
        if now_s is not None:
            self.wind.time_s = now_s

    @property
    def truth(self) -> np.ndarray:
        """Where it is."""
        return self.state[POSITION].copy()

    @property
    def believed(self) -> np.ndarray:
        """Where its autopilot believes it is."""
        return self.state[POSITION] + self.offset

    @property
    def velocity(self) -> np.ndarray:
        """Its true velocity (ENU, m/s)."""
        return self.state[VELOCITY].copy()

    @property
    def attitude(self) -> np.ndarray:
        """Its attitude quaternion (w, x, y, z), body (FLU) to world (ENU)."""
        return self.state[ATTITUDE].copy()

    @property
    def rates(self) -> np.ndarray:
        """Its body rates (FLU, rad/s)."""
        return self.state[RATES].copy()

    def _surfaces_near(self) -> np.ndarray:
        """The heights of the surfaces above, then below, each rotor now."""
        if self.surfaces is None:
            return OPEN_AIR
        rotors = self.state[POSITION] + self.rotors @ quaternion_matrix(self.attitude).T
        return np.concatenate(self.surfaces.heights(rotors))

    def set_estimate(self, estimate: np.ndarray) -> None:
        """The navigation estimate streamed by the ground station replaces the belief."""
        self.offset = np.asarray(estimate, dtype=float).reshape(3) - self.state[POSITION]

    def hold(self) -> None:
        """Hold where the autopilot believes it is."""
        self.target = self.believed.copy()
        self.target_velocity = None

    def stop_at(self, position: np.ndarray) -> None:
        """Stopped dead at ``position`` (a crash): still, level, believing the truth, no
        target."""
        self.state = self._resting(position)
        self.offset = np.zeros(3)
        self.target = None
        self.target_velocity = None

    def step(
        self, dt_s: float, speed_limit_m_s: float, rng: np.random.Generator, noise_m: float
    ) -> np.ndarray:
        """Fly ``dt_s`` (the loop's step) toward the target (none: hold), moving on at the
        setpoint's velocity (its feed-forward) if it has one; return the move the autopilot
        believes it made."""
        if dt_s != self.loop.step_s:
            raise ValueError(f"this body flies steps of {self.loop.step_s} s, not {dt_s}")
        before = self.believed
        target = before if self.target is None else self.target
        wind = CALM if self.wind is None else self.wind.over_step(self.truth, self.loop.substeps)
        start = self._pose()
        self.state, path = self.loop.advance(
            self.state,
            target,
            self.offset,
            speed_limit_m_s,
            wind,
            self._surfaces_near(),
            self.tuning,
            self.target_velocity,
        )
        if self.target is not None and self.target_velocity is not None:
            self.target = self.target + self.target_velocity * dt_s
        if self.drift_rng is not None:  # the filter's velocity error, integrated over the step
            noise = self.drift_rng.normal(0.0, self.loop.loops.velocity_noise_m_s, 3)
            self.offset = self.offset + (self.velocity_bias + noise) * dt_s
        if noise_m > 0:  # a kick to the true position the autopilot does not sense
            kick = rng.normal(0.0, noise_m, 3)
            self.state[POSITION] += kick
            self.offset = self.offset - kick
        self.path = np.vstack([start, path[:-1], self._pose()])
        return self.believed - before
