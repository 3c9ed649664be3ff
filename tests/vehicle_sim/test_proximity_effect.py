"""The ceiling and ground effects: the measured ceiling law (Hsiao and Chirarattananon 2019)
against its formula at five distances, the measured ground law (Sanchez-Cuevas et al. 2017)
and the image law against theirs, a hovering body lifted as the law says, a body tilted under
a deck rolled further, and a vehicle flown up to the deck pulled into it by the effect."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from mission.config.errors import FieldProblem
from mission.config.multicopter_settings import STANDARD_GRAVITY as G
from mission.config.proximity_laws import ceiling_gain, ground_gain
from mission.config.scenario import load_scenario
from mission.world.contact_body import ContactBody
from mission.world.proximity import StructureProximity
from mission.world.surfaces import VerticalSurfaces
from tests.vehicle_sim.rigid_body_alone import RigidBody
from vehicle_sim.dynamics.contact import STRUCTURE, ContactDetector
from vehicle_sim.dynamics.multicopter import Multicopter
from vehicle_sim.dynamics.rigid_body import OPEN_AIR, POSITION, RATES, resting_state

VEHICLE = replace(load_scenario("along").vehicle, dynamics="multicopter", radius_m=None)
BODY = VEHICLE.multicopter
R, H, L = BODY.rotor_radius_m, BODY.rotor_height_m, BODY.lever_m
DECK_UNDERSIDE_M = 8.0  # the along scenario's
STILL = replace(BODY, parasitic_drag_n_s2_m2=(0.0, 0.0, 0.0), rotor_drag_coefficient=0.0)


def _hover_command() -> np.ndarray:
    return np.full(4, BODY.mass_kg * G / 4 / BODY.rotor_thrust_max_n)


def _hsiao(d: float) -> float:
    # T/T0 = gamma^2, gamma = 1/2 + sqrt(1 + (1.6 / 8) (R / d)^2) / 2 (a0 = 1.6, a1 = 0)
    return (0.5 + 0.5 * math.sqrt(1 + 0.2 * (R / d) ** 2)) ** 2


@pytest.mark.parametrize("radii", [4.0, 2.0, 1.0, 0.75, 0.5])
def test_the_measured_ceiling_law_is_its_formula_at_five_distances(radii):
    assert ceiling_gain(BODY, radii * R) == pytest.approx(_hsiao(radii * R), rel=1e-12)


def test_the_measured_ceiling_law_gives_the_gains_quoted_for_it():
    # about 1.10 at R, 1.37 at R / 2 and 2.3 at R / 4 (the last inside the default clip:
    # unclipped), the values quoted for the measured laws
    unclipped = replace(BODY, proximity_clip_radii=0.1, ground_model="none")
    gains = [ceiling_gain(unclipped, k * R) for k in (1.0, 0.5, 0.25)]
    assert gains == pytest.approx([1.10, 1.37, 2.3], abs=0.03)


@pytest.mark.parametrize("height_radii", [3.0, 1.0, 0.5])
def test_the_measured_ground_law_is_sanchez_cuevas_eq_7(height_radii):
    z, d, b = height_radii * R, 2 * L, 2 * math.sqrt(2) * L  # neighbours, opposite rotors
    denominator = (
        1
        - (R / (4 * z)) ** 2
        - R**2 * z / math.sqrt(d**2 + 4 * z**2) ** 3
        - R**2 / 2 * z / math.sqrt(2 * d**2 + 4 * z**2) ** 3
        - 2 * R**2 * z * 2.0 / math.sqrt(b**2 + 4 * z**2) ** 3
    )
    assert ground_gain(BODY, z) == pytest.approx(1 / denominator, rel=1e-12)


@pytest.mark.parametrize("radii, cheeseman_bennett", [(0.5, 4 / 3), (1.0, 16 / 15), (2.0, 64 / 63)])
def test_the_image_law_is_cheeseman_and_bennetts(radii, cheeseman_bennett):
    image = replace(BODY, ceiling_model="image", ground_model="image")
    assert ceiling_gain(image, radii * R) == pytest.approx(cheeseman_bennett, rel=1e-12)
    assert ground_gain(image, radii * R) == pytest.approx(cheeseman_bennett, rel=1e-12)


def test_closer_than_the_clip_the_gain_stays_as_it_is_there():
    at_clip = ceiling_gain(BODY, BODY.proximity_clip_radii * R)
    assert ceiling_gain(BODY, 0.1 * R) == at_clip and ceiling_gain(BODY, -1.0) == at_clip


def _lift_after(settings, surfaces, seconds: float) -> float:
    body = RigidBody(settings, seconds)
    state = resting_state([0.0, 0.0, 5.0], settings)
    return float(body.advance(state, _hover_command(), np.zeros(3), surfaces)[POSITION][2] - 5.0)


@pytest.mark.parametrize("where", ["ceiling", "ground"])
def test_a_hovering_body_near_a_surface_rises_as_the_law_says(where):
    # every rotor within the clip distance throughout (rising 2 cm): a constant excess
    # (gain - 1) g, no drag (STILL): the rise g t^2 (gain - 1) / 2
    gap, rotors = 0.2 * R, 5.0 + H
    if where == "ceiling":
        surfaces, gain = np.array([rotors + gap] * 4 + [-1e6] * 4), ceiling_gain(BODY, gap)
    else:
        surfaces, gain = np.array([1e6] * 4 + [rotors - gap] * 4), ground_gain(BODY, gap)
    t = 0.1
    assert _lift_after(STILL, surfaces, t) == pytest.approx((gain - 1) * G * t**2 / 2, rel=1e-6)
    assert _lift_after(STILL, OPEN_AIR, t) == pytest.approx(0.0, abs=1e-12)
    off = replace(STILL, ceiling_model="none", ground_model="none")
    assert _lift_after(off, surfaces, t) == pytest.approx(0.0, abs=1e-12)


def test_a_body_rolled_under_a_deck_is_rolled_further():
    roll = math.radians(5.0)  # about the nose: the left rotors rise toward the deck
    tilt = np.array([math.cos(roll / 2), math.sin(roll / 2), 0.0, 0.0])
    state = resting_state([0.0, 0.0, 5.0], STILL, tilt)
    body = RigidBody(STILL, 0.02)  # no drag: the thrusts' moments alone
    deck = 5.0 + H + 0.1
    under = body.advance(state, _hover_command(), np.zeros(3), np.array([deck] * 4 + [-1e6] * 4))
    in_open_air = body.advance(state, _hover_command(), np.zeros(3))
    # by hand: two rotors a side at y = +-L, H above the centre; rolled, their heights
    # 5 + H cos(roll) +- L sin(roll); each side's gain the law's at its distance to the deck
    thrust = state[-4]  # each rotor's, as the state starts
    left, right = (
        _hsiao(deck - 5.0 - H * math.cos(roll) - s * L * math.sin(roll)) for s in (1, -1)
    )
    expected_rate = 2 * L * thrust * (left - right) / BODY.inertia_kg_m2[0] * 0.02
    assert under[RATES][0] == pytest.approx(expected_rate, rel=0.03)
    assert abs(in_open_air[RATES][0]) < 1e-9


def _fly_up_to_the_deck(along_world, vehicle, rotor_gap_m: float):
    """A vehicle 1 m under the deck told to climb until its rotors are ``rotor_gap_m`` under
    it: (the rotors' least gap to the deck, the contacts along its substeps)."""
    h = vehicle.multicopter.rotor_height_m
    home = np.array([0.0, 0.0, DECK_UNDERSIDE_M - h - 1.0])
    body = Multicopter.at(home, vehicle, 0.5, surfaces=VerticalSurfaces(along_world.structure))
    body.target = home + [0.0, 0.0, 1.0 - rotor_gap_m]
    shape = ContactBody.of(vehicle.multicopter)
    detector = ContactDetector(StructureProximity(along_world.structure), vehicle.radius_m, shape)
    least, contacts = math.inf, []
    for step in range(12):
        body.step(0.5, 3.0, np.random.default_rng(0), 0.0)
        least = min(least, DECK_UNDERSIDE_M - h - float(body.path[:, 2].max()))
        contacts += detector.along(body.path, 0.5 * step, 0.5 * (step + 1))
    return least, contacts


def test_the_ceiling_effect_pulls_a_vehicle_flown_up_to_the_deck_into_it(along_world):
    off = replace(VEHICLE, multicopter=replace(BODY, ceiling_model="none"))
    # told to stop with its rotors 0.20 m under the deck: 8 cm closer with the effect
    least_on, contacts_on = _fly_up_to_the_deck(along_world, VEHICLE, 0.20)
    least_off, contacts_off = _fly_up_to_the_deck(along_world, off, 0.20)
    assert contacts_on == contacts_off == []
    assert least_off == pytest.approx(0.20, abs=0.01) and least_on < least_off - 0.05
    # at 0.15 m the effect pulls it into the deck, which it would not touch without
    _, contacts_on = _fly_up_to_the_deck(along_world, VEHICLE, 0.15)
    least_off, contacts_off = _fly_up_to_the_deck(along_world, off, 0.15)
    assert contacts_on and contacts_on[0].other == STRUCTURE and contacts_off == []


def test_overlapping_rotors_and_an_infinite_gain_are_refused():
    with pytest.raises(FieldProblem, match="overlap"):
        replace(BODY, rotor_radius_m=0.21)
    with pytest.raises(FieldProblem, match="infinite"):
        replace(BODY, proximity_clip_radii=0.25)
