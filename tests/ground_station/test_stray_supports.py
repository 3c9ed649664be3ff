"""A support the wind blew far outside the workspace, and a support MPC solve that diverged
(the 6 m/s point of the dynamics study: a support 40 m east of the workspace, its next plan
hundreds of metres long, the solve after it never returned): the first is flown straight back
toward its waypoint without an MPC, the second holds and is not used as a warm start."""

from __future__ import annotations

import numpy as np
import pytest

from ground_station.control.plan import plan, solve_supports
from ground_station.control.run_context import build_run_context
from ground_station.support_mpc.mpc import SupportPlan
from mission.link.plan_files import read_plan


def _context(along, along_world):
    plans = read_plan(along)
    waypoints = {
        "work": plans.work,
        **{f"support-{n + 1}": s for n, s in enumerate(plans.supports)},
    }
    return build_run_context(along_world.known(), waypoints, True, 0)


def test_a_support_far_outside_the_workspace_flies_straight_back(along, along_world):
    context, state = _context(along, along_world)
    state.yhat["support-3"] = np.array([63.0, -2.0, 12.0])  # 38 m east of the workspace
    formation = plan(state, context, list(state.yhat))
    plans = solve_supports(state, formation, context)
    stray = plans["support-3"]
    assert stray.status == "OUTSIDE_WORKSPACE"
    reach = along.control.s_max_support_m_s * along.control.t_cont_s
    target = context.support_waypoints["support-3"][state.k]
    step = stray.command - state.yhat["support-3"]
    assert np.linalg.norm(step) == pytest.approx(reach, abs=1e-9)
    np.testing.assert_allclose(
        step / reach,
        (target - state.yhat["support-3"]) / np.linalg.norm(target - state.yhat["support-3"]),
        atol=1e-12,
    )
    assert all(plans[n].status != "OUTSIDE_WORKSPACE" for n in ("support-1", "support-2"))


class _Diverging:
    """A planner whose solve for support-2 returns a path hundreds of metres long."""

    def __init__(self, planner) -> None:
        self.planner = planner

    def plan_all(self, requests):
        plans = self.planner.plan_all(requests)
        bad = plans["support-2"]
        wild = bad.path + np.arange(len(bad.path))[:, None] * [150.0, -140.0, 100.0]
        plans["support-2"] = SupportPlan(
            wild, "SOLVER_RET_UNKNOWN", 1.0, bad.blocked, False, bad.anchors
        )
        return plans


def test_a_diverged_plan_holds_the_support_and_is_no_warm_start(along, along_world):
    context, state = _context(along, along_world)
    context.planner = _Diverging(context.planner)
    before = state.yhat["support-2"].copy()
    plans = solve_supports(state, plan(state, context, list(state.yhat)), context)
    assert plans["support-2"].status == "REJECTED_DIVERGED"
    np.testing.assert_array_equal(plans["support-2"].command, before)
    assert "support-2" not in state.warm and "support-1" in state.warm
    np.testing.assert_array_equal(state.last_support_command["support-2"], np.zeros(3))
