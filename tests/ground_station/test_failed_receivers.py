"""The ground station's defined reaction to a support whose GNSS or camera has failed
(docs/ground-station.md): without a (plausible) fix the support is dead-reckoned from its
commands, neither fused nor learned from; without a sighting its estimate is its fix, not fused
and not learned from; the others go on as before."""

from __future__ import annotations

import copy

import numpy as np

from ground_station.control.cycle import control_cycle
from ground_station.control.run_context import build_run_context
from ground_station.estimation.localize import IMPLAUSIBLE_FIX_M, SupportReport
from mission.link.plan_files import read_plan


def _context(along, along_world):
    plan = read_plan(along)
    waypoints = {"work": plan.work, **{f"support-{n + 1}": s for n, s in enumerate(plan.supports)}}
    return build_run_context(along_world.known(), waypoints, True, 0), plan


def _report(along_world, plan, n, rng, fix=True, relative=True) -> SupportReport:
    y = plan.supports[n][0]
    sample = along_world.gnss.sample_fix(y, rng)
    seen = along_world.camera.observe(y, plan.work[0], rng)
    return SupportReport(
        f"support-{n + 1}",
        sample.position_m if fix else None,
        seen.relative_m if relative else None,
    )


def test_a_support_without_gnss_or_camera_is_neither_fused_nor_learned_from(along, along_world):
    (context, state), plan = _context(along, along_world)
    rng = np.random.default_rng(3)
    healthy = [_report(along_world, plan, n, rng) for n in range(3)]
    assert all(r.fix is not None and r.relative is not None for r in healthy)
    far = np.array(along.world.workspace.max_m) + [5000.0, 0, 0]  # GARBAGE is farther
    failed = [
        SupportReport("support-1", far, healthy[0].relative),  # garbage: far outside
        SupportReport("support-2", healthy[1].fix, None),  # camera lost
        healthy[2],
    ]
    before = copy.deepcopy(state.yhat)
    state.last_support_command["support-1"] = np.array([0.2, -0.1, 0.0])
    decision = control_cycle(state, failed, context)
    names = [m.name for m in decision.measurements]
    assert names == ["support-1", "support-2", "support-3"]
    assert decision.measurements[0].fix_m is None  # the implausible fix is no fix
    assert decision.fusion.contributing == ("support-3",)
    np.testing.assert_array_equal(state.yhat["support-1"], before["support-1"] + [0.2, -0.1, 0])
    np.testing.assert_array_equal(state.yhat["support-2"], healthy[1].fix)
    assert decision.betas["support-1"] is None and decision.betas["support-2"] is None
    # G learns from support-3 alone: the same map as a cycle with only its report
    (alone_context, alone_state), _ = _context(along, along_world)
    only = control_cycle(alone_state, [healthy[2]], alone_context)
    assert only.updated_voxels == decision.updated_voxels > 0
    np.testing.assert_array_equal(alone_context.g.values, context.g.values)
    np.testing.assert_array_equal(alone_state.xhat, state.xhat)


def test_plausible_fixes_are_left_alone(along, along_world):
    (context, state), plan = _context(along, along_world)
    rng = np.random.default_rng(4)
    reports = [_report(along_world, plan, n, rng) for n in range(3)]
    edge = np.array(along.world.workspace.max_m) + [IMPLAUSIBLE_FIX_M / 2, 0, 0]
    reports[0] = SupportReport("support-1", edge, reports[0].relative)
    decision = control_cycle(state, reports, context)
    assert decision.measurements[0].fix_m is not None
