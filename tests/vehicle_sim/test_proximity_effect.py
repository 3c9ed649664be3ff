"""The ceiling and ground effects: the thrust gain against Cheeseman and Bennett's law at three
distances, a hovering body lifted by it as the drag law says, a body tilted under a deck rolled
further, and a vehicle hovering under the deck that a gust and the ceiling effect push into it
caught by the contact detection (along its substeps, between two steps' ends)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from mission.config.errors import FieldProblem
from mission.config.multicopter_settings import STANDARD_GRAVITY as G
from mission.config.scenario import load_scenario
from mission.world.proximity import StructureProximity
from mission.world.surfaces import VerticalSurfaces
from tests.vehicle_sim.rigid_body_alone import RigidBody
from vehicle_sim.dynamics.contact import STRUCTURE, ContactDetector
from vehicle_sim.dynamics.multicopter import Multicopter
from vehicle_sim.dynamics.rigid_body import (
    OPEN_AIR,
    POSITION,
    RATES,
    proximity_gain,
    resting_state,
)

VEHICLE = load_scenario("along").vehicle
BODY = VEHICLE.multicopter
R = BODY.rotor_radius_m
DECK_UNDERSIDE_M = 8.0  # the along scenario's
GAP_M = 0.4  # the body's centre under the deck: 15 cm from touching it
GUST_M_S = 1.2  # straight up for a second


def _hover_command() -> np.ndarray:
    return np.full(4, BODY.mass_kg * G / 4 / BODY.rotor_thrust_max_n)


@pytest.mark.parametrize("radii, cheeseman_bennett", [(0.5, 4 / 3), (1.0, 16 / 15), (2.0, 64 / 63)])
def test_the_gain_is_cheeseman_and_bennetts_at_three_distances(radii, cheeseman_bennett):
    # T/T0 = 1 / (1 - (R / 4 d)^2): 1 / (1 - 1/4), 1 / (1 - 1/16), 1 / (1 - 1/64)
    gain = float(proximity_gain(BODY.ceiling_effect_k, R, BODY.proximity_clip_radii, radii * R))
    assert gain == pytest.approx(cheeseman_bennett, rel=1e-12)


def test_closer_than_the_clip_the_gain_stays_as_it_is_there():
    at_clip = float(proximity_gain(1 / 16, R, 0.5, 0.5 * R))
    assert float(proximity_gain(1 / 16, R, 0.5, 0.1 * R)) == at_clip
    assert float(proximity_gain(1 / 16, R, 0.5, -1.0)) == at_clip  # a rotor through it


def _lift_after(settings, surfaces, seconds: float) -> float:
    body = RigidBody(settings, seconds)
    state = resting_state([0.0, 0.0, 5.0], settings)
    return float(body.advance(state, _hover_command(), np.zeros(3), surfaces)[POSITION][2] - 5.0)


@pytest.mark.parametrize("where", ["ceiling", "ground"])
def test_a_hovering_body_near_a_surface_rises_as_the_drag_law_says(where):
    # every rotor within the clip distance throughout (rising 2 cm from the ground): the gain
    # is 4/3, an excess of g / 3
    gap = 0.2 * R
    if where == "ceiling":
        surfaces = np.array([5.0 + gap] * 4 + [-1e6] * 4)
    else:
        surfaces = np.array([1e6] * 4 + [5.0 - gap] * 4)
    t, m, k = 0.1, BODY.mass_kg, BODY.drag_n_per_m_s
    excess = G / 3
    expected = excess * m / k * (t - m / k * (1 - math.exp(-k * t / m)))
    assert _lift_after(BODY, surfaces, t) == pytest.approx(expected, rel=1e-6)
    assert _lift_after(BODY, OPEN_AIR, t) == pytest.approx(0.0, abs=1e-12)
    off = replace(BODY, ceiling_effect_k=0.0, ground_effect_k=0.0)
    assert _lift_after(off, surfaces, t) == pytest.approx(0.0, abs=1e-12)


def test_a_body_rolled_under_a_deck_is_rolled_further():
    roll = math.radians(5.0)  # about the nose: the left rotors rise toward the deck
    tilt = np.array([math.cos(roll / 2), math.sin(roll / 2), 0.0, 0.0])
    state = resting_state([0.0, 0.0, 5.0], BODY, tilt)
    body = RigidBody(BODY, 0.02)
    deck = np.array([5.1] * 4 + [-1e6] * 4)
    under = body.advance(state, _hover_command(), np.zeros(3), deck)
    in_open_air = body.advance(state, _hover_command(), np.zeros(3))
    # by hand: two rotors a side, arm_y = arm sin 45 from the roll axis, their heights
    # +- arm_y sin(roll); each side's gain 1 / (1 - (R / 4 d)^2) at its distance d
    arm_y = BODY.arm_m * math.sin(math.radians(45))
    thrust = state[-4]  # each rotor's, as the state starts
    left, right = (1 / (1 - (R / 4 / (0.1 - s * arm_y * math.sin(roll))) ** 2) for s in (1, -1))
    moment = 2 * arm_y * thrust * (left - right)
    expected_rate = moment / BODY.inertia_kg_m2[0] * 0.02
    assert under[RATES][0] == pytest.approx(expected_rate, rel=0.03)
    assert abs(in_open_air[RATES][0]) < 1e-9


class _Updraft:
    """A gust straight up for ``seconds``, then still air (the wind of the parts around the
    contact check: the body, the surfaces and the detector are the real ones)."""

    def __init__(self, speed_m_s: float, seconds: float, step_s: float) -> None:
        self.speed, self.steps_left = speed_m_s, round(seconds / step_s)

    def over_step(self, position, substeps: int) -> np.ndarray:
        up = self.speed if self.steps_left > 0 else 0.0
        self.steps_left -= 1
        return np.tile([0.0, 0.0, up], (substeps, 1))


def _fly_under_the_deck(along_world, vehicle, gust_m_s: float):
    """(the highest point, the contacts along its substeps, those between its steps' ends)."""
    home = np.array([0.0, 0.0, DECK_UNDERSIDE_M - GAP_M])
    body = Multicopter.at(home, vehicle, 0.5, surfaces=VerticalSurfaces(along_world.structure))
    body.wind = _Updraft(gust_m_s, 1.0, 0.5)
    body.hold()
    detector = ContactDetector(StructureProximity(along_world.structure), vehicle.radius_m)
    along, ends, peak = [], [], 0.0
    for step in range(6):
        body.step(0.5, 3.0, np.random.default_rng(0), 0.0)
        peak = max(peak, float(body.path[:, 2].max()))
        start_s, end_s = 0.5 * step, 0.5 * (step + 1)
        along += detector.along(body.path, start_s, end_s)
        ends += detector.along(body.path[[0, -1]], start_s, end_s)  # the step's ends only
    return peak, along, ends


def test_a_gust_and_the_ceiling_effect_push_a_hovering_vehicle_into_the_deck_caught(along_world):
    peak, contacts, between_ends = _fly_under_the_deck(along_world, VEHICLE, GUST_M_S)
    assert [c.other for c in contacts] == [STRUCTURE] and between_ends == []
    touch = contacts[0]
    assert DECK_UNDERSIDE_M - touch.position_m[2] < VEHICLE.radius_m
    assert 1.0 < touch.time_s < 1.5  # rising past its step's start, down again by its end
    # the same gust without the ceiling effect stays clear: the effect made the difference
    off = replace(VEHICLE, multicopter=replace(BODY, ceiling_effect_k=0.0))
    peak_off, contacts_off, _ = _fly_under_the_deck(along_world, off, GUST_M_S)
    assert contacts_off == [] and peak_off < peak
    # and in still air the autopilot holds its place within 2 cm against the ceiling effect
    peak_calm, calm_contacts, _ = _fly_under_the_deck(along_world, VEHICLE, 0.0)
    assert calm_contacts == [] and peak_calm == pytest.approx(DECK_UNDERSIDE_M - GAP_M, abs=0.02)


def test_overlapping_rotors_and_an_infinite_gain_are_refused():
    with pytest.raises(FieldProblem, match="overlap"):
        replace(BODY, rotor_radius_m=0.15)
    with pytest.raises(FieldProblem, match="infinite"):
        replace(BODY, ceiling_effect_k=0.25, proximity_clip_radii=0.5)
