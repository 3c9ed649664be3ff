"""Hold when blind: with no contributing support the work UAV holds where its last command
took it, no waypoint is reached on that dead-reckoned estimate, and the supports plan around a
work UAV that stays put."""

from __future__ import annotations

import numpy as np
import pytest

from ground_station.control.cycle import run_cycle
from ground_station.control.run_context import build_run_context
from ground_station.estimation.localize import SupportReport
from mission.link.plan_files import read_plan
from mission.world.model import KnownWorld


def _waypoints(plan) -> dict[str, np.ndarray]:
    return {"work": plan.work, **{f"support-{n + 1}": s for n, s in enumerate(plan.supports)}}


@pytest.fixture(scope="module")
def station(along):
    return build_run_context(KnownWorld(along), _waypoints(read_plan(along)), True, 0)


def _blind_reports(context) -> list[SupportReport]:
    """Every support has its fix; none sees the work UAV."""
    return [SupportReport(n, w[0].copy(), None) for n, w in context.support_waypoints.items()]


def test_a_blind_cycle_holds_the_work_uav_where_its_last_command_took_it(station):
    context, state = station
    state.xhat = np.array([-11.0, -2.5, 7.0])
    state.last_work_command = np.array([0.1, 0.05, 0.0])  # what the last cycle commanded
    held = state.xhat + state.last_work_command
    k_before = state.k
    for _ in range(3):  # and it stays held, cycle after cycle
        output = run_cycle(state, _blind_reports(context), context)
        assert output.fusion.blind
        np.testing.assert_array_equal(output.work_target, held)
        np.testing.assert_array_equal(state.xhat, held)
        np.testing.assert_array_equal(state.last_work_command, np.zeros(3))
        assert np.all(output.work_prediction.path == held)
        assert output.arrived is None and state.k == k_before
        assert set(output.support_plans) == set(context.support_waypoints)


def test_no_waypoint_is_reached_on_a_dead_reckoned_estimate(station):
    context, state = station
    state.k = 0
    target = context.work_waypoints[0]
    state.xhat = target - np.array([0.05, 0.0, 0.0])  # its last command ends on the waypoint
    state.last_work_command = np.array([0.05, 0.0, 0.0])
    output = run_cycle(state, _blind_reports(context), context)
    np.testing.assert_allclose(state.xhat, target)
    assert output.arrived is None and state.k == 0
