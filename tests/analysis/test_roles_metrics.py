"""The ``roles`` block of summary.json from hand-made records and truth, against counts made
by hand."""

from __future__ import annotations

import numpy as np
import pytest

from mission.analysis.roles import role_metrics
from mission.analysis.trace import RunTrace
from mission.config.scenario import load_scenario
from mission.world.model import World


@pytest.fixture(scope="module")
def piers():
    scenario = load_scenario("piers")
    return scenario, World(scenario)


def _records() -> list[dict]:
    """Six cycles of 0.5 s: support-1 inspects for three (reaching two waypoints) and returns
    for one; support-3 inspects for the last two; the work UAV arrives twice."""
    roles = [
        ("formation", "formation", "formation"),
        ("inspecting", "formation", "formation"),
        ("inspecting", "formation", "formation"),
        ("inspecting", "formation", "formation"),
        ("returning", "formation", "inspecting"),
        ("formation", "formation", "inspecting"),
    ]
    records = []
    for i, (a, b, c) in enumerate(roles):
        records.append(
            {
                "t": 0.5 * i,
                "arrived": 1 if i == 2 else (2 if i == 5 else None),
                "roles": {
                    "roles": {"support-1": a, "support-2": b, "support-3": c},
                    "next_inspection": {"support-1": min(i, 2), "support-2": 0, "support-3": 0},
                },
            }
        )
    return records


def test_minutes_switches_and_waypoints_are_counted_from_the_records(piers):
    scenario, world = piers
    trace = RunTrace()
    trace.inspections_done, trace.completion = 3.0, 2.5
    for system in (1, 2, 3, 4):
        trace.truth[(system, 0.0)] = np.array([-18.0, -6.5, 2.0])
    block = role_metrics(trace, _records(), world, scenario)
    assert block["all_done_s"] == 3.0  # the inspections' end, not the work UAV's
    half_minutes = {"formation": 12, "inspecting": 5, "returning": 1}  # of the 18 support-cycles
    assert block["support_minutes"] == {
        r: pytest.approx(n / 120, abs=5e-5) for r, n in half_minutes.items()
    }
    assert block["role_switches"] == 4  # out, back (returning), in; support-3 out
    assert block["waypoints_reached"]["work"] == {"reached": 2, "of": 23}
    assert block["waypoints_reached"]["support-1"] == {"reached": 2, "of": 4}
    assert block["policy"] == "fixed"


def test_the_work_uavs_error_is_split_by_the_sky_at_its_true_position(piers):
    scenario, world = piers
    trace = RunTrace(max_gap_s=1.0)
    # in the open at the west pier's face, then under the deck
    for t, truth, error in [(0.0, (-18.0, -6.5, 2.0), 0.1), (0.5, (0.0, 0.0, 7.0), 0.4)]:
        trace.truth[(1, t)] = np.array(truth)
        trace.estimates[t] = np.array(truth) + [error, 0.0, 0.0]
    block = role_metrics(trace, [], world, scenario)
    assert block["work_error_m"]["open"]["mean"] == pytest.approx(0.1)
    assert block["work_error_m"]["shadow"]["mean"] == pytest.approx(0.4)
    assert block["all_done_s"] is None  # inspections in the scenario, none reported done
