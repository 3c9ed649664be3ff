"""A setpoint with a velocity (ArduPilot GUIDED's position and velocity target): the target
moves on at it, for a kinematic point and a flying quadrotor alike, until a position-only
setpoint or the failsafe; the forms and values it cannot take are refused and said."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from ground_station.links.outgoing import position_target
from mission.link.vehicle_identity import VehicleIdentity
from mission.world.model import World
from vehicle_sim.mavlink import modes
from vehicle_sim.vehicle import Vehicle

HOME = np.array([0.0, -10.0, 7.0])  # in the open, south of the deck
EAST = np.array([0.4, 0.0, 0.0])  # m/s


def _guided(world: World) -> tuple[Vehicle, list]:
    sent: list = []
    vehicle = Vehicle(
        VehicleIdentity.parse("support-1"), world.scenario, world, HOME, 0, sent.append
    )
    vehicle.change_mode(modes.GUIDED)
    vehicle.arm(True)
    sent.clear()
    return vehicle, sent


def _send(vehicle: Vehicle, message) -> None:
    message.pack(mavlink2.MAVLink(None, srcSystem=255, srcComponent=190))
    vehicle.handle(message, 0.0)


@pytest.fixture(scope="module")
def flying_world(along_world) -> World:
    scenario = along_world.scenario
    return World(
        replace(scenario, vehicle=replace(scenario.vehicle, dynamics="multicopter", radius_m=None))
    )


@pytest.mark.parametrize("flying", [False, True])
def test_the_target_moves_on_at_the_setpoints_velocity(along_world, flying_world, flying):
    vehicle, _ = _guided(flying_world if flying else along_world)
    _send(vehicle, position_target(HOME, 0, 2, EAST))
    for _ in range(3):  # 1.5 s, inside the failsafe's 2 s
        vehicle.step()
    assert vehicle.kinematics.target == pytest.approx(HOME + 1.5 * EAST)
    moved = vehicle.kinematics.believed - HOME
    if flying:  # a quadrotor from rest behind it by its velocity loop's lag (~0.5 s)
        assert 0.3 < moved[0] < 0.6 and np.abs(moved[1:]).max() < 0.1
    else:  # a kinematic point follows the moving target exactly
        assert moved == pytest.approx(1.5 * EAST, abs=1e-9)
    _send(vehicle, position_target(HOME + 1.5 * EAST, 0, 2))  # a position only: it stops there
    vehicle.step()
    assert vehicle.kinematics.target_velocity is None
    assert vehicle.kinematics.target == pytest.approx(HOME + 1.5 * EAST)


@pytest.mark.parametrize(
    ("mask", "velocity", "said"),
    [
        (0b0000_1100_0000_0000, (0.4, 0.0, 0.0), "type_mask"),  # acceleration not ignored
        (0b0000_1101_1101_0000, (0.4, 0.0, 0.0), "type_mask"),  # only part of the velocity
        (0b0000_1101_1100_0000, (float("nan"), 0.0, 0.0), "velocity out of range"),
        (0b0000_1101_1100_0000, (0.0, 51.0, 0.0), "velocity out of range"),
    ],
)
def test_a_setpoint_it_cannot_take_is_refused_and_said(along_world, mask, velocity, said):
    vehicle, sent = _guided(along_world)
    message = position_target(HOME + [1.0, 0.0, 0.0], 0, 2, np.zeros(3))
    message.type_mask, (message.vx, message.vy, message.vz) = mask, velocity
    _send(vehicle, message)
    text = "".join(m.text for m in sent if m.get_type() == "STATUSTEXT")  # chunks, in order
    assert text.startswith("Setpoint rejected") and said in text
    assert vehicle.kinematics.target is None or np.allclose(vehicle.kinematics.target, HOME)


def test_a_setpoints_velocity_is_held_to_the_speed_limit_and_stops_at_the_fence(along_world):
    vehicle, _ = _guided(along_world)
    limit = vehicle.speed_limit_m_s
    _send(vehicle, position_target(HOME, 0, 2, np.array([0.0, 10.0 * limit, 0.0])))
    assert np.linalg.norm(vehicle.kinematics.target_velocity) == pytest.approx(limit)
    # north toward the deck (its south face at y = -5, from z 8): the target moving at 1 m/s
    # stops short of it rather than carry the vehicle in
    below_deck = np.array([0.0, -6.2, 8.5])  # beside the deck, level with it
    vehicle, _ = _guided(along_world)
    _send(vehicle, position_target(below_deck, 0, 2, np.array([0.0, 1.0, 0.0])))
    for _ in range(3):
        vehicle.step()
    assert vehicle.kinematics.target_velocity is None
    assert vehicle.kinematics.target[1] < -5.0
