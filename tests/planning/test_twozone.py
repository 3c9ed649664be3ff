"""The two-zone scenarios (N = 3..6): each zone lies on one support's shipped path and on no
other's, the two supports' segments are side by side in the task, and placing them afresh on
the shipped files gives the zones the scenario files hold."""

from __future__ import annotations

import numpy as np
import pytest

from mission.config.scenario import load_scenario
from mission.link.plan_files import read_plan
from mission.planning.zone_placement import inside, path_samples, place_along_pair

TWO_ZONE = {"twozone-3": 3, "twozone-4": 4, "twozone": 5, "twozone-6": 6}


@pytest.mark.parametrize("name", TWO_ZONE)
def test_each_zone_encloses_one_supports_path_and_no_others(name):
    scenario = load_scenario(name)
    assert scenario.task.supports == TWO_ZONE[name] and len(scenario.world.zones) == 2
    plan = read_plan(scenario)
    owners = []
    for zone in scenario.world.zones:
        enclosed = [inside(zone.box, path_samples(path)).sum() * 0.05 for path in plan.supports]
        holders = [n for n, metres in enumerate(enclosed) if metres > 0]
        assert len(holders) == 1 and enclosed[holders[0]] >= 2.0, (zone.name, enclosed)
        owners.append(holders[0])
    assert owners[0] != owners[1]
    placed = place_along_pair(plan, scenario.world.workspace)
    assert [z for _, _, z in placed] == [z.box for z in scenario.world.zones]
    segments = [segment for _, segment, _ in placed]
    assert abs(segments[0] - segments[1]) <= 1


def test_a_pair_needs_two_supports_with_room_for_a_zone():
    from mission.link.plan_files import Plan

    flat = np.array([[0.0, 0.0, 5.0], [0.5, 0.0, 5.0], [1.0, 0.0, 5.0]])  # segments < 2 m
    plan = Plan(work=flat, supports=np.array([flat, flat + [0.0, 5.0, 0.0]]))
    with pytest.raises(ValueError, match="no two supports"):
        place_along_pair(plan, load_scenario("along").world.workspace)
