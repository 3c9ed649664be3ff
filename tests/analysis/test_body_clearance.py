"""The tlog's judge of a flying quadrotor's touch: its rotor rims and frame along its truth,
at its attitude, as the vehicle checks them itself."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from mission.analysis.body_clearance import attitudes_at, body_touches
from mission.config.scenario import load_scenario
from mission.world.contact_body import ContactBody
from mission.world.frames import quaternion_matrix
from mission.world.proximity import StructureProximity

BODY = replace(load_scenario("along").vehicle, dynamics="multicopter", radius_m=None).multicopter


def _rolled(degrees: float) -> np.ndarray:
    roll = math.radians(degrees)
    return quaternion_matrix([math.cos(roll / 2), math.sin(roll / 2), 0.0, 0.0])


def test_a_level_body_under_the_deck_inside_its_bounding_sphere_does_not_touch(along_world):
    proximity, body = StructureProximity(along_world.structure), ContactBody.of(BODY)
    times = np.array([0.0, 0.5, 1.0])
    # the centre 0.15 m under the deck's underside (z 8): its rotors' plane 10 cm under it
    centres = np.array([[-2.0, 0.0, 7.85], [0.0, 0.0, 7.85], [2.0, 0.0, 7.85]])
    level = np.repeat(np.eye(3)[None], 3, axis=0)
    assert not body_touches(proximity, body, (times, centres, level))
    rolled = np.repeat(_rolled(20.0)[None], 3, axis=0)  # its left rotors up into the deck
    assert body_touches(proximity, body, (times, centres, rolled))
    unknown = centres.copy()
    unknown[1] = np.nan  # no segment with both ends known: nothing judged
    assert not body_touches(proximity, body, (times, unknown, rolled))


def test_a_vehicles_attitude_is_its_latest_sample_at_or_before_each_time():
    attitudes = {(2, 0.5): _rolled(10.0), (2, 1.0): _rolled(20.0), (3, 0.5): _rolled(30.0)}
    found = attitudes_at(attitudes, 2, np.array([0.0, 0.5, 0.7, 1.0, 4.0]))
    expected = [_rolled(10.0), _rolled(10.0), _rolled(10.0), _rolled(20.0), _rolled(20.0)]
    assert np.allclose(found, expected)
    assert np.allclose(attitudes_at(attitudes, 4, np.array([1.0])), np.eye(3)[None])
