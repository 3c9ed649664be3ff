"""The run's wind is one field: every flying vehicle builds it from the run's seed, not from its
own instance, so two vehicles sample the same gusts at the same point and time, whatever
vehicles the run has; a vehicle's wind keeps the simulated clock."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from mission.link.vehicle_identity import VehicleIdentity
from mission.world.model import World
from vehicle_sim.mavlink import modes
from vehicle_sim.vehicle import Vehicle


@pytest.fixture(scope="module")
def windy_flying(along) -> World:
    """Along with quadrotors in a 3 m/s west wind."""
    world = replace(along.world, wind=replace(along.world.wind, speed_m_s=3.0))
    vehicle = replace(along.vehicle, dynamics="multicopter")
    return World(replace(along, world=world, vehicle=vehicle))


def _vehicle(world: World, name: str, home, seed: int) -> Vehicle:
    identity = VehicleIdentity.parse(name)
    return Vehicle(identity, world.scenario, world, np.asarray(home, dtype=float), seed, [].append)


def test_two_vehicles_of_a_run_feel_one_field(windy_flying):
    work = _vehicle(windy_flying, "work", [0.0, -8.0, 6.0], seed=3)
    support = _vehicle(windy_flying, "support-2", [5.0, 10.0, 9.0], seed=3)
    another_run = _vehicle(windy_flying, "support-2", [5.0, 10.0, 9.0], seed=4)
    point = np.array([2.0, 12.0, 7.0])  # where either might fly, in the open
    felt = []
    for vehicle in (work, support, another_run):
        vehicle.kinematics.wind.time_s = 20.0
        felt.append(vehicle.kinematics.wind.over_step(point, 125))
    assert np.array_equal(felt[0], felt[1])  # the same gusts, whichever vehicle samples them
    assert not np.allclose(felt[0], felt[2])  # another seed, another field
    # 3 m downwind, 1 s later (the field carried at 3 m/s), the gusts the support felt
    work.kinematics.wind.time_s = 21.0
    downwind = work.kinematics.wind.over_step(point + [3.0, 0.0, 0.0], 1)[0]
    mean = work.kinematics.wind.field.mean(point)
    assert downwind - mean == pytest.approx(felt[1][0] - mean, abs=1e-5)


def test_a_vehicles_wind_keeps_the_simulated_clock(windy_flying):
    vehicle = _vehicle(windy_flying, "support-1", [0.0, 12.0, 6.0], seed=0)
    vehicle.join_clock(7.5)  # joining a running clock: its first step ends at 7.5 s
    vehicle.change_mode(modes.GUIDED)
    vehicle.arm(True)
    for _ in range(3):
        start_s = vehicle.sim_time_s
        vehicle.step()
        # the step sampled the field from its start, on the simulated clock
        assert vehicle.kinematics.wind.time_s == pytest.approx(start_s + 0.5)
    assert vehicle.sim_time_s == pytest.approx(7.0 + 1.5)
