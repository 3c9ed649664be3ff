"""The work UAV's own GNSS fix (roles.policy: dynamic): used only when it should be, a
hand-built cycle each way. It is used in the open sky where G expects little error and it
agrees with the supports' relative estimate (combined with it by their information) or where
the supports give none (the work UAV is then not blind); it is not used without a fix, in the
deck's shadow, where G has learned multipath, or far from the supports' estimate; with the
paper's fixed roles it is never read."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from ground_station.control.cycle import control_cycle
from ground_station.control.run_context import build_run_context
from ground_station.estimation.fusion import FusionResult, LogDensity
from ground_station.estimation.gnss_map import LocalizabilityMap
from ground_station.estimation.localize import SupportReport
from ground_station.roles.own_fix import combined_estimate, judge
from mission.link.plan_files import read_plan

OPEN_SKY = np.array([0.0, -12.0, 7.0])  # 7 m beside the deck's edge, beside no pier
UNDER_DECK = np.array([0.0, 0.0, 7.0])


def _map(world) -> LocalizabilityMap:
    scenario = world.scenario
    return LocalizabilityMap(world.map_grid(), world.sigma0_map().sigma_m, scenario.map, True)


def _relative(xhat, sigma_m: float) -> FusionResult:
    """A fusion whose one consistent support puts the work UAV at ``xhat``."""
    density = LogDensity.of(np.asarray(xhat, dtype=float), np.eye(3) * sigma_m**2)
    return FusionResult(
        np.asarray(xhat, dtype=float), ("support-1",), ("support-1",), False, np.eye(1), (density,)
    )


BLIND = FusionResult(None, (), (), False, np.zeros((0, 0)), ())


def test_without_a_fix_or_in_the_decks_shadow_the_fix_is_not_used(along_world):
    g, roles = _map(along_world), along_world.scenario.roles
    assert judge(None, BLIND, g, along_world, roles).reason == "no fix"
    verdict = judge(UNDER_DECK, _relative(UNDER_DECK, 0.1), g, along_world, roles)
    assert verdict.reason == "shadow" and not verdict.used


def test_in_the_open_a_fix_that_agrees_is_used_and_weighed_by_its_information(along_world):
    g, roles = _map(along_world), along_world.scenario.roles
    sigma0 = float(along_world.gnss.sigma0(OPEN_SKY[None])[0])
    assert sigma0 < roles.own_fix_max_sigma_m
    xhat = OPEN_SKY + [0.1, 0.0, 0.0]
    verdict = judge(OPEN_SKY, _relative(xhat, 0.1), g, along_world, roles)
    # G holds sigma_0 per 1 m voxel, interpolated: near the point's own value
    assert verdict.used and verdict.sigma_m == pytest.approx(sigma0, rel=0.1)
    # by hand: the fix isotropic with sigma^2 / 3 a axis, the support's 0.1^2; the distance
    # in sigmas along x, and the information-weighted mean
    own_var, relative_var = verdict.sigma_m**2 / 3, 0.01
    assert verdict.distance_sigmas == pytest.approx(0.1 / np.sqrt(own_var + relative_var))
    combined = combined_estimate(OPEN_SKY, verdict, _relative(xhat, 0.1))
    weight = (1 / own_var) / (1 / own_var + 1 / relative_var)
    np.testing.assert_allclose(combined, weight * OPEN_SKY + (1 - weight) * xhat, atol=1e-12)


def test_a_fix_far_from_the_supports_estimate_or_where_g_learned_multipath_is_not_used(
    along_world,
):
    g, roles = _map(along_world), along_world.scenario.roles
    far = judge(OPEN_SKY, _relative(OPEN_SKY + [1.0, 0.0, 0.0], 0.1), g, along_world, roles)
    assert far.reason == "disagrees" and far.distance_sigmas > roles.own_fix_agreement_sigmas
    centre = g.grid.index_of(OPEN_SKY[None])[0]
    g.values[tuple(slice(c - 2, c + 3) for c in centre)] = 1.0  # multipath learned here
    learned = judge(OPEN_SKY, _relative(OPEN_SKY, 0.1), g, along_world, roles)
    assert learned.reason == "map" and learned.sigma_m > roles.own_fix_max_sigma_m


def _blind_cycle(along, along_world, policy: str):
    """A cycle in which no support sees the work UAV, which has a fix in the open sky."""
    scenario = replace(along, roles=replace(along.roles, policy=policy))
    plan = read_plan(along)
    waypoints = {"work": plan.work, **{f"support-{n + 1}": s for n, s in enumerate(plan.supports)}}
    world = along_world.known()
    context, state = build_run_context(world, waypoints, True, 0)
    context.scenario = scenario
    state.xhat = OPEN_SKY + [0.02, 0.0, 0.0]
    rng = np.random.default_rng(1)
    reports = [
        SupportReport(f"support-{n + 1}", along_world.gnss.sample_fix(s[0], rng).position_m, None)
        for n, s in enumerate(plan.supports)
    ]
    return control_cycle(state, reports, context, OPEN_SKY.copy()), state


def test_with_no_support_seeing_it_the_work_uav_flies_on_its_own_fix(along, along_world):
    decision, state = _blind_cycle(along, along_world, "dynamic")
    assert decision.fusion.blind and decision.own_fix.used and not decision.blind
    np.testing.assert_array_equal(state.xhat, OPEN_SKY)
    # the paper's fixed roles never read it: the same cycle is blind
    fixed, fixed_state = _blind_cycle(along, along_world, "fixed")
    assert fixed.blind and fixed.own_fix is None
    np.testing.assert_array_equal(fixed_state.xhat, OPEN_SKY + [0.02, 0.0, 0.0])
