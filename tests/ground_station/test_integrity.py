"""The integrity monitor against hand computations: the chi-square arithmetic against scipy,
a cycle with a known bias giving its statistic by hand, the flag raised at the gate and not
below, the liar told apart (or not), restoration, a bias that follows its support taken back
from G, and an excluded support's wider margins."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy import stats

from ground_station.estimation.fusion import SupportMeasurement
from ground_station.estimation.gnss_map import LocalizabilityMap
from ground_station.integrity.monitor import IntegrityMonitor
from ground_station.state.station_state import StationState
from ground_station.support_mpc.margins import widened
from mission.config.settings import MapSettings
from mission.maths.chi_square import (
    detectable_noncentrality,
    gate,
    noncentral_cdf_3,
    survival,
)
from mission.world.grid import VoxelGrid

SIGMA_GNSS = np.diag([0.01, 0.01, 0.04])  # m^2
SIGMA_R = np.diag([0.0025, 0.0025, 0.0025])
PREVIOUS = np.diag([0.02, 0.02, 0.05])  # the last estimate's covariance
Q = 0.05  # motion_sigma_m


@pytest.mark.parametrize("dof", [1, 2, 3, 4, 6, 9])
def test_the_survival_function_and_its_gate_are_scipys(dof):
    for x in (0.1, 2.0, 11.3, 25.9, 80.0):
        assert survival(x, dof) == pytest.approx(stats.chi2.sf(x, dof), rel=1e-10, abs=1e-300)
    for rate in (1e-2, 1e-5, 1e-9):
        assert gate(rate, dof) == pytest.approx(stats.chi2.isf(rate, dof), rel=1e-9)


def test_the_noncentral_distribution_and_the_detectable_bias_are_scipys():
    for x, lam in ((25.9, 0.5), (25.9, 40.0), (3.0, 3.0), (60.0, 64.0)):
        assert noncentral_cdf_3(x, lam) == pytest.approx(stats.ncx2.cdf(x, 3, lam), rel=1e-9)
    lam = detectable_noncentrality(1e-5, 1e-3)
    assert stats.ncx2.cdf(stats.chi2.isf(1e-5, 3), 3, lam) == pytest.approx(1e-3, rel=1e-6)


def _settings(along, **changes):
    base = dataclasses.replace(along.integrity, enabled=True, motion_sigma_m=Q)
    return dataclasses.replace(base, **changes)


def _support(name, fix, relative=None) -> SupportMeasurement:
    return SupportMeasurement(
        name,
        np.array(fix, dtype=float),
        SIGMA_GNSS,
        None if relative is None else np.array(relative, dtype=float),
        None if relative is None else SIGMA_R,
    )


def _primed(along, names=("support-1",), **changes) -> tuple[IntegrityMonitor, StationState]:
    """A monitor that has seen one cycle: each support at the origin, last covariance known,
    commanded 0.3 m east."""
    monitor = IntegrityMonitor(_settings(along, **changes), multicopter=False, voxel_m=1.0)
    state = StationState(np.zeros(3), {n: np.zeros(3) for n in names}, 1)
    for name in names:
        _at(monitor, state, name, np.zeros(3))
        state.last_support_command[name] = np.array([0.3, 0.0, 0.0])
    return monitor, state


def _at(monitor, state, name, position):
    """The support's estimate and its motion test's reference at ``position`` (what the
    monitor's settling after a fusion would leave), with the reference's covariance."""
    watch = monitor.watch(name)
    watch.reference, watch.reference_covariance = np.array(position, float), PREVIOUS.copy()
    watch.covariance = PREVIOUS.copy()
    state.yhat[name] = np.array(position, float)


def _motion_statistic_by_hand(bias: np.ndarray) -> float:
    variances = np.diag(SIGMA_GNSS) + np.diag(PREVIOUS) + Q**2
    return float(np.sum(bias**2 / variances))


def test_a_known_step_gives_its_statistic_by_hand_and_is_excluded_at_the_gate(along):
    gate_1 = gate(1e-5, 3)
    for scale, excluded in ((0.99, False), (1.01, True)):
        monitor, state = _primed(along, sustain_cycles=1)
        direction = np.array([1.0, 0.0, 0.0])
        variance = SIGMA_GNSS[0, 0] + PREVIOUS[0, 0] + Q**2
        bias = direction * np.sqrt(scale * gate_1 * variance)  # T = scale x the gate
        fix = np.array([0.3, 0.0, 0.0]) + bias
        verdict = monitor.check([_support("support-1", fix)], state)
        statistic = verdict.statistics["support-1"]["motion"]
        assert statistic == pytest.approx(_motion_statistic_by_hand(bias), rel=1e-12)
        assert statistic == pytest.approx(scale * gate_1, rel=1e-9)
        assert ("support-1" in verdict.excluded) is excluded
        assert "support-1" in verdict.withheld  # over the suspect gate either way
        if excluded:
            size = f"{np.linalg.norm(bias):.1f}"  # 0.9 m
            assert (
                verdict.events[0].text == f"Integrity: support-1 excluded (motion test, {size} m)"
            )


def test_a_smaller_bias_is_excluded_once_two_cycles_sum_past_their_gate(along):
    monitor, state = _primed(along, sustain_cycles=2)
    one, two = gate(1e-5, 3), gate(1e-5, 6)
    variance = SIGMA_GNSS[0, 0] + PREVIOUS[0, 0] + Q**2
    bias = np.array([np.sqrt(0.6 * two * variance), 0.0, 0.0])  # 0.6 x gate_2 each: under one
    assert 0.6 * two < one
    first = monitor.check([_support("support-1", np.array([0.3, 0, 0]) + bias)], state)
    assert not first.excluded and "support-1" in first.withheld
    state.last_support_command["support-1"] = np.zeros(3)  # a withheld support: dead-reckoned
    _at(monitor, state, "support-1", [0.3, 0.0, 0.0])
    second = monitor.check([_support("support-1", np.array([0.3, 0, 0]) + bias)], state)
    assert second.excluded == {"support-1"}


def _formation(biased: int, count: int, along, **changes):
    names = tuple(f"support-{n + 1}" for n in range(count))
    monitor = IntegrityMonitor(_settings(along, **changes), multicopter=False, voxel_m=1.0)
    state = StationState(np.zeros(3), {n: np.zeros(3) for n in names}, 1)
    work = np.array([0.0, 0.0, 5.0])
    supports = []
    for n, name in enumerate(names):
        position = np.array([3.0 * n - 3.0, 6.0, 7.0])
        fix = position + (np.array([2.0, 0.0, 0.0]) if n == biased else 0.0)
        supports.append(_support(name, fix, work - position))
    return monitor, state, supports


def test_with_three_supports_the_formation_test_blames_the_one_that_lies(along):
    monitor, state, supports = _formation(biased=1, count=3, along=along, sustain_cycles=1)
    verdict = monitor.check(supports, state)
    assert verdict.excluded == {"support-2"} and not verdict.ambiguous
    assert verdict.events[0].test == "formation"
    # by hand: support-2 against the mean of the other two (equal covariances)
    nu = supports[1].mu - (supports[0].mu + supports[2].mu) / 2
    s = supports[1].sigma + (SIGMA_GNSS + SIGMA_R) / 2
    assert verdict.statistics["support-2"]["formation"] == pytest.approx(
        float(nu @ np.linalg.solve(s, nu)), rel=1e-12
    )


def test_two_supports_that_disagree_cannot_be_told_apart_and_both_are_withheld(along):
    monitor, state, supports = _formation(biased=0, count=2, along=along)
    verdict = monitor.check(supports, state)
    assert verdict.ambiguous == ("support-1", "support-2")
    assert verdict.withheld == {"support-1", "support-2"} and not verdict.excluded
    assert not verdict.events


def _excluded_then_quiet(along, moved_m: float) -> list[str]:
    """A support excluded for a 2.2 m step, then quiet for three cycles, having moved
    ``moved_m`` east between its last biased cycle and its first quiet one: the events."""
    monitor, state = _primed(along, sustain_cycles=1, recovery_cycles=3)
    big = np.array([0.3 + 2.2, 0.0, 0.0])
    assert monitor.check([_support("support-1", big)], state).excluded == {"support-1"}
    state.last_support_command["support-1"] = np.zeros(3)
    here = np.array([0.3, 0.0, 0.0])
    _at(monitor, state, "support-1", here)
    for _ in range(3):  # still biased, here, as long as it takes to be restored
        monitor.check([_support("support-1", here + [2.2, 0, 0])], state)
    there = here + [moved_m, 0.0, 0.0]
    _at(monitor, state, "support-1", there)
    kinds = []
    for _ in range(3):  # the fix is back where the support is
        verdict = monitor.check([_support("support-1", there)], state)
        kinds += [event.kind for event in verdict.events]
    assert not verdict.excluded
    return kinds


def test_a_bias_gone_where_its_support_left_it_was_a_places(along):
    assert _excluded_then_quiet(along, moved_m=1.5) == ["restored"]


def test_a_bias_gone_while_its_support_stayed_in_its_voxel_was_the_receivers(along):
    assert _excluded_then_quiet(along, moved_m=0.2) == ["receiver", "restored"]


def test_a_bias_that_follows_its_support_is_its_receivers_and_g_forgets_it(along, along_world):
    grid = VoxelGrid(origin_m=np.array([-20.0, -20.0, 0.0]), voxel_m=1.0, shape=(40, 40, 16))
    settings = MapSettings(voxel_size_m=1.0, eta=0.3, neighborhood=1.5, no_fix_sigma_m=5.0)
    g = LocalizabilityMap(grid, np.full(grid.shape, 0.15), settings)
    before = g.values.copy()
    monitor, state = _primed(along, sustain_cycles=1, receiver_travel_m=3.0)
    work = np.array([0.0, 0.0, 5.0])
    glitch = np.array([0.0, 2.2, 0.0])
    events = []
    for step in range(8):  # east at 1 m a cycle, its fix 2.2 m north all the way
        position = np.array([float(step), 0.0, 6.0])
        support = _support("support-1", position + glitch, work - position)
        verdict = monitor.check([support], state)
        if verdict.excluded:
            _at(monitor, state, "support-1", position)  # placed by the formation
            events = list(monitor.settle([support], state, _blind(), verdict).events)
            monitor.learn_excluded(g, [support], state.yhat, events)
        _at(monitor, state, "support-1", position)
        state.last_support_command["support-1"] = np.array([1.0, 0.0, 0.0])
        if any(e.kind == "receiver" for e in events):
            break
    assert [e.kind for e in events if e.kind == "receiver"] == ["receiver"]
    np.testing.assert_allclose(g.values, before, atol=1e-12)  # all it taught, taken back


def _blind():
    from ground_station.estimation.fusion import FusionResult

    return FusionResult(None, (), (), False, np.zeros((0, 0)), ())


def test_an_excluded_supports_margins_are_wider_and_unused_slots_stay_unused():
    normals = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]  # three slots, the middle unused
    offsets = [0.75, -1.0, 0.75]
    out = widened(np.array(normals + offsets), 1.0)
    np.testing.assert_allclose(out[:9], normals)
    np.testing.assert_allclose(out[9:], [1.75, -1.0, 1.75])


def test_the_protection_radii_by_hand():
    from ground_station.integrity.protection import (
        detectable_bias,
        fault_shift,
        no_fault_radius,
    )

    covariance = np.diag([0.04, 0.01, 0.09])
    k2 = gate(1e-3, 3)
    assert no_fault_radius(covariance, k2) == pytest.approx(np.sqrt(k2 * 0.09))
    lam = detectable_noncentrality(1e-5, 1e-3)
    assert detectable_bias(covariance, lam) == pytest.approx(np.sqrt(lam * 0.09))
    # two equal supports: P = Sigma / 2, each weighs 1/2; the other's MDB bounds each bias
    sigma = SIGMA_GNSS + SIGMA_R
    information = {"a": np.linalg.inv(sigma), "b": np.linalg.inv(sigma)}
    shift = fault_shift(sigma / 2, information, {"a": sigma, "b": sigma}, lam, None)
    assert shift == pytest.approx(0.5 * np.sqrt(lam * np.linalg.eigvalsh(2 * sigma)[-1]))
    # fused alone, the motion test's bound, or none
    alone = {"a": np.linalg.inv(sigma)}
    assert fault_shift(sigma, alone, {"a": sigma}, lam, 0.7) == pytest.approx(0.7)
    assert fault_shift(sigma, alone, {"a": sigma}, lam, None) == float("inf")


def test_the_plain_float_inverse_and_quadratic_are_numpys():
    from ground_station.integrity.small import inverse3, quadratic3

    rng = np.random.default_rng(3)
    for _ in range(50):
        half = rng.normal(size=(3, 3))
        matrix = half @ half.T + 0.01 * np.eye(3)
        np.testing.assert_allclose(inverse3(matrix), np.linalg.inv(matrix), rtol=1e-9, atol=1e-9)
        v = rng.normal(size=3)
        assert quadratic3(v, inverse3(matrix)) == pytest.approx(v @ np.linalg.solve(matrix, v))
    with pytest.raises(ValueError, match="singular"):
        inverse3(np.zeros((3, 3)))


def test_a_receiver_that_reports_itself_poor_widens_its_own_tests(along):
    monitor, state = _primed(along, sustain_cycles=1)
    bias = np.array([0.8, 0.0, 0.0])
    fix = np.array([0.3, 0.0, 0.0]) + bias
    plain = monitor.check([_support("support-1", fix)], state).statistics["support-1"]
    monitor, state = _primed(along, sustain_cycles=1)
    reported = np.diag([0.25, 0.25, 0.5])  # it says 0.5 m horizontally
    poor = dataclasses.replace(_support("support-1", fix), reported_m2=reported)
    verdict = monitor.check([poor], state)
    wide = verdict.statistics["support-1"]["motion"]
    by_hand = 0.8**2 / (reported[0, 0] + PREVIOUS[0, 0] + Q**2)
    assert wide == pytest.approx(by_hand, rel=1e-12) and wide < plain["motion"]
    assert not verdict.excluded  # the 0.8 m it may be off is within what it said


def test_a_vehicle_that_did_not_fly_its_command_is_tested_where_its_autopilot_says_it_is(along):
    """Its setpoint refused, it held: the fix where it held, against the 0.3 m it was told."""
    monitor, state = _primed(along, sustain_cycles=1)
    held = np.zeros(3)
    told = monitor.check([_support("support-1", held)], state).statistics["support-1"]["motion"]
    assert told == pytest.approx(_motion_statistic_by_hand(np.array([-0.3, 0.0, 0.0])))
    monitor, state = _primed(along, sustain_cycles=1)
    reported = dataclasses.replace(_support("support-1", held), belief_m=held)  # it says: here
    verdict = monitor.check([reported], state)
    assert verdict.statistics["support-1"]["motion"] == pytest.approx(0.0)


def test_the_formation_test_takes_the_camera_at_the_predicted_range_where_that_is_wider(along):
    wide = np.diag([0.09, 0.0025, 0.0025])  # the camera at the range the others predict
    monitor = IntegrityMonitor(
        _settings(along), multicopter=False, voxel_m=1.0, camera=lambda relative: wide
    )
    _, state, supports = _formation(biased=1, count=3, along=along)
    verdict = monitor.check(supports, state)
    nu = supports[1].mu - (supports[0].mu + supports[2].mu) / 2
    s = SIGMA_GNSS + wide + (SIGMA_GNSS + SIGMA_R) / 2  # its own camera widened; the others'
    assert verdict.statistics["support-2"]["formation"] == pytest.approx(
        float(nu @ np.linalg.solve(s, nu)), rel=1e-12
    )
