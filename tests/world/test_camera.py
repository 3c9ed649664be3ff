"""Camera model: Jacobian, Sigma_r and sampling against independent estimates."""

from __future__ import annotations

import numpy as np
import pytest

from mission.world.camera import CameraModel, spherical, spherical_jacobian


def _to_cartesian(d: float, phi: float, theta: float) -> np.ndarray:
    return d * np.array([np.cos(phi) * np.cos(theta), np.cos(phi) * np.sin(theta), np.sin(phi)])


@pytest.fixture(scope="module")
def camera(along) -> CameraModel:
    return CameraModel(along.camera)


@pytest.mark.parametrize("z", [[6.0, 8.0, -1.0], [-3.0, 2.0, 4.0], [0.5, -9.0, -2.5]])
def test_spherical_round_trip_and_jacobian_by_finite_differences(z):
    z = np.array(z)
    d, phi, theta = spherical(z)
    np.testing.assert_allclose(_to_cartesian(d, phi, theta), z, atol=1e-12)
    jac = spherical_jacobian(d, phi, theta)
    h = 1e-6
    numeric = np.column_stack(
        [
            (
                _to_cartesian(*(np.array([d, phi, theta]) + h * e))
                - _to_cartesian(*(np.array([d, phi, theta]) - h * e))
            )
            / (2 * h)
            for e in np.eye(3)
        ]
    )
    np.testing.assert_allclose(jac, numeric, atol=1e-7)


def test_sigma_d_is_the_quadratic(camera):
    assert float(camera.sigma_d(10.0)) == pytest.approx(0.002 * 100 + 0.005 * 10 + 0.02)
    assert float(camera.sigma_d(10.0)) == pytest.approx(0.27)


def test_sigma_r_matches_monte_carlo_through_the_exact_transform(camera):
    """Perturb (d, phi, theta) by their sigmas, map exactly, compare with J D J^T."""
    rng = np.random.default_rng(11)
    z = np.array([7.0, -6.0, 2.0])
    d, phi, theta = spherical(z)
    sig = camera.sigmas(z)
    n = 40_000
    samples = np.array([d, phi, theta]) + sig * rng.standard_normal((n, 3))
    cart = samples[:, :1] * np.column_stack(
        (
            np.cos(samples[:, 1]) * np.cos(samples[:, 2]),
            np.cos(samples[:, 1]) * np.sin(samples[:, 2]),
            np.sin(samples[:, 1]),
        )
    )
    empirical = np.cov(cart.T)
    model = camera.covariance(z)
    scale = np.sqrt(np.outer(np.diag(model), np.diag(model)))
    np.testing.assert_allclose(empirical / scale, model / scale, atol=0.03)


def test_sampled_observations_have_sigma_r_covariance(camera):
    rng = np.random.default_rng(5)
    z = np.array([-4.0, 9.0, -3.0])
    samples = camera.sample(np.tile(z, (20_000, 1)), rng)
    model = camera.covariance(z)
    whitened = np.linalg.solve(np.linalg.cholesky(model), (samples - z).T).T
    np.testing.assert_allclose(whitened.mean(axis=0), 0.0, atol=0.03)
    np.testing.assert_allclose(np.cov(whitened.T), np.eye(3), atol=0.04)


def test_observability_range_and_line_of_sight(along_world):
    camera = along_world.camera
    under_deck = np.array([0.0, 0.0, 6.0])
    beside = np.array([0.0, -9.0, 6.0])
    above_deck = np.array([0.0, 0.0, 12.0])
    far = np.array([0.0, -40.0, 6.0])
    assert camera.observable(beside, under_deck)[0]
    assert not camera.observable(above_deck, under_deck)[0], "the deck blocks the sight line"
    assert not camera.observable(far, under_deck)[0], "beyond camera range"
    rng = np.random.default_rng(0)
    seen = camera.observe(beside, under_deck, rng)
    hidden = camera.observe(above_deck, under_deck, rng)
    assert seen.valid and np.linalg.norm(seen.relative_m - (under_deck - beside)) < 1.0
    assert not hidden.valid and hidden.relative_m is None


def test_observe_samples_have_sigma_r_covariance(along_world):
    """The per-step scalar path draws from the same N(z, Sigma_r(z)) as sample()."""
    camera = along_world.camera
    rng = np.random.default_rng(9)
    observer, target = np.array([2.0, -12.0, 6.0]), np.array([-1.0, -3.0, 5.0])
    z = target - observer
    samples = np.array([camera.observe(observer, target, rng).relative_m for _ in range(8000)])
    whitened = np.linalg.solve(np.linalg.cholesky(camera.covariance(z)), (samples - z).T).T
    np.testing.assert_allclose(whitened.mean(axis=0), 0.0, atol=0.05)
    np.testing.assert_allclose(np.cov(whitened.T), np.eye(3), atol=0.06)
