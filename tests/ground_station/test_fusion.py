"""Selective fusion and support feedback against hand computations and calibrated rates."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.stats import multivariate_normal, pearsonr

from ground_station.estimation.fusion import (
    FusionResult,
    LogDensity,
    SupportMeasurement,
    correlation_matrix,
    log_densities,
    selective_fusion,
    support_feedback,
)
from mission.config.settings import FusionSettings
from mission.link.plan_files import read_plan


def _measure(world, truth_work, supports, rng, bias=None) -> list[SupportMeasurement]:
    out = []
    for n, y in enumerate(supports):
        offset = bias if (bias is not None and n == 0) else np.zeros(3)
        fix = world.gnss.sample_fix(y, rng, offset)
        obs = world.camera.observe(y, truth_work, rng)
        _, sigma_gnss = world.gnss.sigma_gnss(fix.position_m[None])
        out.append(
            SupportMeasurement(
                f"support-{n + 1}",
                fix.position_m,
                sigma_gnss[0],
                obs.relative_m,
                world.camera.covariance(obs.relative_m),
            )
        )
    return out


def _rates(world, plan, bias, cycles=400, seed=0, rho_threshold=None):
    rng = np.random.default_rng(seed)
    settings = world.scenario.fusion
    if rho_threshold is not None:
        settings = dataclasses.replace(settings, rho_threshold=rho_threshold)
    kept_all, excluded_biased, errors = 0, 0, []
    for c in range(cycles):
        i = c % 15
        truth = plan.work[i]
        measurements = _measure(world, truth, plan.supports[:, i], rng, bias)
        predicted = truth + rng.normal(0, 0.15, 3)  # last estimate + command: ~0.15 m off
        result = selective_fusion(measurements, predicted, settings, rng)
        kept_all += len(result.consistent) == 3 and not result.fallback
        excluded_biased += "support-1" not in result.consistent
        errors.append(np.linalg.norm(result.xhat - truth))
    return kept_all / cycles, excluded_biased / cycles, float(np.mean(errors))


@pytest.fixture(scope="module")
def plan(along):
    return read_plan(along)


def test_without_bias_every_support_is_kept(along_world, plan):
    kept, _, error = _rates(along_world, plan, None)
    print(f"no bias: all kept in {kept:.1%} of cycles, mean error {error:.3f} m")
    assert kept >= 0.95


def test_a_1m_bias_is_excluded_and_the_estimate_stays_good(along_world, plan):
    _, excluded, error_biased = _rates(along_world, plan, np.array([1.0, 0.0, 0.0]))
    _, _, error_clean = _rates(along_world, plan, None)
    print(
        f"1 m bias: excluded in {excluded:.1%} of cycles, error {error_biased:.3f} m "
        f"(unbiased {error_clean:.3f} m)"
    )
    _, _, error_naive = _rates(along_world, plan, np.array([1.0, 0.0, 0.0]), rho_threshold=-1.0)
    print(f"  fusing every support regardless: error {error_naive:.3f} m")
    assert excluded >= 0.90
    assert error_biased <= error_clean + 0.08, "near the unbiased fusion's error"
    assert error_biased < 0.7 * error_naive, "selection removes most of the bias"


def test_the_log_density_matches_scipy():
    rng = np.random.default_rng(1)
    a = rng.normal(size=(3, 3))
    sigma = a @ a.T + np.eye(3)
    mu = rng.normal(size=3)
    x = rng.normal(size=(5, 3))
    np.testing.assert_allclose(
        LogDensity.of(mu, sigma)(x), multivariate_normal(mu, sigma).logpdf(x), rtol=1e-10
    )


def test_densities_in_one_call_equal_each_alone_bit_for_bit():
    rng = np.random.default_rng(2)
    densities = []
    for _ in range(4):
        a = rng.normal(size=(3, 3))
        densities.append(LogDensity.of(rng.normal(size=3), a @ a.T + 0.1 * np.eye(3)))
    x = rng.normal(size=(700, 3)) * 5
    alone = [
        -0.5 * (np.sum(z * z, axis=0) + d.log_det + 3 * np.log(2 * np.pi))
        for d in densities
        for z in [np.linalg.solve(d.factor, (x - d.mu).T)]
    ]
    assert np.array_equal(log_densities(densities, x), np.array(alone))
    one = densities[0](x[0])  # a point as a vector: a scalar, as the one-at-a-time formula
    z = np.linalg.solve(densities[0].factor, x[0] - densities[0].mu)
    assert np.ndim(one) == 0
    assert one == -0.5 * (np.sum(z * z, axis=0) + densities[0].log_det + 3 * np.log(2 * np.pi))
    nothing = FusionResult(None, (), (), False, np.zeros((0, 0)), ())
    assert np.array_equal(nothing.log_p(x[:4]), np.zeros(4))  # no support in S: log P = 0


def test_correlation_matrix_matches_pearson_on_densities():
    rng = np.random.default_rng(2)
    x = rng.normal(size=(200, 3))
    gaussians = [
        (np.zeros(3), np.eye(3)),
        (np.array([0.3, 0, 0]), 2 * np.eye(3)),
        (np.array([3.0, 0, 0]), 0.2 * np.eye(3)),
    ]
    logs = [LogDensity.of(mu, s)(x) for mu, s in gaussians]
    rho = correlation_matrix(logs)
    for i in range(3):
        for j in range(3):
            expected = 1.0 if i == j else pearsonr(np.exp(logs[i]), np.exp(logs[j]))[0]
            assert rho[i, j] == pytest.approx(expected, abs=1e-9)


def test_feedback_matches_a_hand_computation():
    mu_a, mu_b = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    sigma = 0.5 * np.eye(3)
    fusion = FusionResult(
        np.array([0.5, 0.5, 0.0]),
        ("a", "b"),
        ("a", "b"),
        False,
        np.eye(2),
        (LogDensity.of(mu_a, sigma), LogDensity.of(mu_b, sigma)),
    )
    r = np.array([0.0, 0.0, 2.0])
    support = SupportMeasurement("a", mu_a - r, np.eye(3) * 0.01, r, np.eye(3) * 0.01)
    feedback = support_feedback(support, fusion, np.zeros(3), np.zeros(3))
    # log P(x) = sum_n -|x - mu_n|^2 / (2 * 0.5) + const
    log_p = lambda x: -np.sum((x - mu_a) ** 2) - np.sum((x - mu_b) ** 2)  # noqa: E731
    beta = np.exp(log_p(fusion.xhat)) / (np.exp(log_p(mu_a)) + np.exp(log_p(fusion.xhat)))
    assert feedback.beta == pytest.approx(beta, rel=1e-12)
    expected = beta * fusion.xhat + (1 - beta) * mu_a - r
    np.testing.assert_allclose(feedback.yhat, expected, atol=1e-12)


def test_feedback_fallbacks():
    fusion = FusionResult(np.zeros(3), (), (), False, np.eye(0), ())
    no_fix = SupportMeasurement("a", None, None, np.ones(3), np.eye(3))
    no_obs = SupportMeasurement("a", np.array([1.0, 2, 3]), np.eye(3), None, None)
    moved = support_feedback(no_fix, fusion, np.array([5.0, 5, 5]), np.array([0.5, 0, 0]))
    np.testing.assert_array_equal(moved.yhat, [5.5, 5, 5])
    np.testing.assert_array_equal(
        support_feedback(no_obs, fusion, np.zeros(3), np.zeros(3)).yhat, [1.0, 2, 3]
    )


def test_blind_and_fallback():
    rng = np.random.default_rng(0)
    settings = FusionSettings(50, 10, 1.0, 0.0, "contributing")
    nothing = [SupportMeasurement("a", None, None, None, None)]
    assert selective_fusion(nothing, np.zeros(3), settings, rng).blind
    far = [
        SupportMeasurement(n, np.array(p, float), 0.01 * np.eye(3), np.zeros(3), 0.01 * np.eye(3))
        for n, p in (("a", [30, 0, 0]), ("b", [-30, 0, 0]), ("c", [0, 30, 0]))
    ]
    result = selective_fusion(far, np.zeros(3), settings, rng)
    assert result.fallback and set(result.consistent) == {"a", "b", "c"}


def test_agreement_counts_against_the_contributing_supports_or_against_all_n():
    """Five supports, four contributing: a and b agree, c and d each agree only with
    themselves. Against the four that contribute, a and b reach half (2 of 4) and form S;
    against N = 5 (the paper's count) nobody reaches 2.5, S is empty and all four are fused."""

    def support(name, position, observed=True):
        relative = np.zeros(3) if observed else None
        sigma = 0.01 * np.eye(3) if observed else None
        return SupportMeasurement(
            name, np.array(position, float), 0.01 * np.eye(3), relative, sigma
        )

    supports = [
        support("a", [0.0, 0.0, 0.0]),
        support("b", [0.05, 0.0, 0.0]),
        support("c", [2.0, 0.0, 0.0]),
        support("d", [0.0, -2.0, 0.0]),
        support("e", [0.0, 2.0, 0.0], observed=False),
    ]
    for agreement, fallback, consistent in (
        ("contributing", False, {"a", "b"}),
        ("paper", True, {"a", "b", "c", "d"}),
    ):
        settings = FusionSettings(300, 100, 1.0, 0.0, agreement)
        result = selective_fusion(supports, np.zeros(3), settings, np.random.default_rng(0))
        assert result.fallback is fallback and set(result.consistent) == consistent


def test_a_cycles_covariances_in_one_batch_equal_one_at_a_time(along_world, plan):
    """localize batches Sigma_GNSS and Sigma_r over the supports: the numbers
    are those of each support alone, bit for bit (with a support lacking an observation and
    one lacking a fix among them)."""
    from ground_station.estimation.localize import SupportReport, localize

    known = along_world.known()

    rng = np.random.default_rng(2)
    for i in range(0, len(plan.work), 3):
        values = []
        for n, y in enumerate(plan.supports[:, i]):
            fix = along_world.gnss.sample_fix(y, rng).position_m
            relative = plan.work[i] - y + rng.normal(0, 0.05, 3)
            values.append(
                SupportReport(
                    f"support-{n + 1}",
                    None if n == 2 else fix,
                    None if n == 1 else relative,
                    np.eye(3) * 0.01,
                )
            )
        together = localize(values, known)
        for value, joint in zip(values, together):
            (alone,) = localize([value], known)
            for field in ("fix_m", "sigma_gnss_m2", "relative_m", "sigma_relative_m2"):
                a, b = getattr(alone, field), getattr(joint, field)
                assert (a is None) == (b is None), field
                if a is not None:
                    assert np.array_equal(a, b), field
        assert together[0].contributes and not together[1].contributes
