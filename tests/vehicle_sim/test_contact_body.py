"""A flying quadrotor's contact body: its rotor tips strike a pier face the old 0.25 m sphere
would have missed, its flat body hovers under a deck closer than its bounding sphere, a tilt
brings a rim into the deck, and the bounding radius defaults to the rotor tips."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from mission.config.scenario import load_scenario
from mission.world.contact_body import ContactBody
from mission.world.proximity import StructureProximity
from vehicle_sim.dynamics.contact import GROUND, STRUCTURE, ContactDetector

VEHICLE = replace(load_scenario("along").vehicle, dynamics="multicopter", radius_m=None)
BODY = VEHICLE.multicopter
PIER_FACE_X = -15.0  # the along scenario's west pier spans x -17 to -15, y -3 to 3, to z 8
LEVEL = np.array([1.0, 0.0, 0.0, 0.0])
TOLERANCE = BODY.rotor_radius_m * math.sin(math.pi / 12)  # half the rim points' spacing


@pytest.fixture(scope="module")
def detector(along_world) -> ContactDetector:
    proximity = StructureProximity(along_world.structure)
    return ContactDetector(proximity, VEHICLE.radius_m, ContactBody.of(BODY))


def _held_at(detector, position, attitude=LEVEL):
    pose = np.concatenate([position, attitude])
    return detector.along(np.array([pose, pose]), 0.0, 0.5)


def test_the_bounding_radius_defaults_to_the_rotor_tips():
    tips = math.sqrt(2) * BODY.lever_m + BODY.rotor_radius_m
    assert VEHICLE.radius_m == pytest.approx(tips) and tips == pytest.approx(0.410, abs=1e-3)
    kinematic = replace(load_scenario("along").vehicle, radius_m=None)
    assert kinematic.radius_m == 0.25


def test_a_rotor_tip_striking_a_pier_face_is_contact(detector):
    # level, nose east, east of the pier: the rear rotors' rims reach lever + rotor radius =
    # 0.327 m behind; beside the pier's east face with the tips 1 cm into it, and clear of it
    reach = BODY.lever_m + BODY.rotor_radius_m
    struck = _held_at(detector, np.array([PIER_FACE_X + reach - 0.01, 0.0, 4.0]))
    clear = _held_at(detector, np.array([PIER_FACE_X + reach + TOLERANCE + 0.01, 0.0, 4.0]))
    assert [c.other for c in struck] == [STRUCTURE] and clear == []
    # the frame's 0.25 m sphere alone would not have seen the strike
    sphere = ContactDetector(detector.proximity, 0.25)
    assert sphere.along(np.array([[PIER_FACE_X + reach - 0.01, 0.0, 4.0]] * 2), 0.0, 0.5) == []


def test_a_level_body_under_the_deck_closer_than_its_bounding_sphere_is_clear(detector):
    # the rotors' plane 5 cm above the centre, 10 cm under the deck: inside the 0.41 m sphere
    centre = 8.0 - BODY.rotor_height_m - 0.1
    assert _held_at(detector, np.array([0.0, 0.0, centre])) == []
    # rolled 20 degrees, the left rotors' rims rise into the deck
    roll = math.radians(20.0)
    rolled = np.array([math.cos(roll / 2), math.sin(roll / 2), 0.0, 0.0])
    assert [c.other for c in _held_at(detector, np.array([0.0, 0.0, centre]), rolled)] == [
        STRUCTURE
    ]


def test_a_body_sinking_to_the_ground_touches_it_with_its_frame(detector):
    # the frame's core (half the lever) is its lowest part when level
    assert _held_at(detector, np.array([0.0, -20.0, BODY.lever_m / 2 + 0.01])) == []
    touching = _held_at(detector, np.array([0.0, -20.0, BODY.lever_m / 2 - 0.01]))
    assert [c.other for c in touching] == [GROUND]


def test_a_flying_vehicle_checks_its_rims_and_frame_not_its_bounding_sphere(along_world):
    from mission.link.vehicle_identity import VehicleIdentity
    from mission.world.model import World
    from vehicle_sim.mavlink import modes
    from vehicle_sim.vehicle import Vehicle

    # no ceiling effect: the measured law would pull a vehicle this close into the deck
    calm = replace(VEHICLE, multicopter=replace(BODY, ceiling_model="none"))
    flying = World(replace(along_world.scenario, vehicle=calm))
    sent: list = []
    home = np.array([0.0, 0.0, 8.0 - 0.2])  # 0.2 m under the deck: inside the 0.41 m sphere
    vehicle = Vehicle(VehicleIdentity.parse("work"), flying.scenario, flying, home, 0, sent.append)
    vehicle.change_mode(modes.GUIDED)
    vehicle.arm(True)
    for _ in range(4):
        vehicle.step()
    assert vehicle.watch.detector.body is not None
    assert not [m for m in sent if m.get_type() == "STATUSTEXT" and "structure" in m.text]
