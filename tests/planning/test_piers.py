"""The piers scenario: an inspection that leaves the deck's shadow. Its shipped plan
keeps the run's margins (that the planner reproduces its plans byte for byte is Along's test);
its work path lies partly in the open, where the station's sky model expects a fix, and partly
in the shadow, where it does not; each support has inspection waypoints of its own, clear of
the structure."""

from __future__ import annotations

from pathlib import Path

import pytest

from mission.config.scenario import load_scenario
from mission.link.plan_check import check_inspections_placed, check_plan_files
from mission.link.plan_files import read_plan, vehicle_names
from mission.world.model import KnownWorld


@pytest.fixture(scope="module")
def piers():
    return load_scenario("piers")


def test_the_shipped_plan_keeps_the_margins_and_the_inspections_are_clear(piers):
    world = KnownWorld(piers)
    check_plan_files(world, Path(piers.task.waypoints_dir), vehicle_names(3))  # raises on a problem
    check_inspections_placed(world)
    assert sorted(i.vehicle for i in piers.task.inspections) == vehicle_names(3)[1:]
    work = read_plan(piers).work
    has_fix, _ = world.gnss.sigma_gnss(work)
    assert has_fix[:6].all() and has_fix[-6:].all(), "the piers and the edges in the open"
    assert not has_fix[8:16].any(), "the underside in the shadow"
