"""How a vehicle moves: the kinematic point (the default) or the flying quadrotor in the
scenario's wind, by ``vehicle.dynamics``."""

from __future__ import annotations

from typing import Any

import numpy as np

from mission.world.model import World
from vehicle_sim.dynamics.kinematics import Kinematics


def vehicle_motion(
    world: World, home: np.ndarray, wind_seed: int, drift_rng: np.random.Generator
) -> Any:
    """The motion of a vehicle hovering at ``home``: a :class:`Kinematics`, or a
    :class:`~vehicle_sim.dynamics.multicopter.Multicopter` (imported only then: casadi is no
    small import for a vehicle that does not need it) in the wind of the run's ``wind_seed``."""
    scenario = world.scenario
    if scenario.vehicle.dynamics == "multicopter":
        from mission.world.surfaces import VerticalSurfaces
        from vehicle_sim.dynamics.multicopter import Multicopter

        return Multicopter.at(
            home,
            scenario.vehicle,
            scenario.control.t_cont_s,
            scenario.world.wind,
            list(world.structure.boxes),
            wind_seed,
            drift_rng,
            VerticalSurfaces(world.structure),
        )
    return Kinematics.at(home)
