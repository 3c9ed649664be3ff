"""Map G updates against a hand computation; G_s against the 1-D Hermite formula."""

from __future__ import annotations

import dataclasses
import itertools

import casadi as ca
import numpy as np
import pytest

from ground_station.estimation.gnss_map import (
    LocalizabilityMap,
    casadi_hermite,
    hermite_zero_slope,
    inlined_hermite,
)
from mission.config.settings import Box
from mission.world.grid import VoxelGrid

GRID = VoxelGrid(np.array([0.0, 0.0, 0.0]), 1.0, (5, 5, 5))


def _map(along, eta=0.3, neighborhood=1.0, adaptive=True, start=0.2) -> LocalizabilityMap:
    settings = dataclasses.replace(along.map, eta=eta, neighborhood=neighborhood)
    return LocalizabilityMap(GRID, np.full(GRID.shape, start), settings, adaptive)


def test_update_equals_a_hand_computation(along):
    g = _map(along)
    g.values[2, 2, 3] = 0.5  # a voxel of its own, to check the per-voxel difference term
    before = g.values.copy()
    fix, yhat = np.array([3.1, 2.5, 2.5]), np.array([2.5, 2.7, 2.4])  # yhat in voxel (2, 2, 2)
    e = np.linalg.norm(fix - yhat)
    changed = g.update(fix, yhat)
    expected = before.copy()
    for i, j, k in itertools.product(range(5), repeat=3):
        if max(abs(i - 2), abs(j - 2), abs(k - 2)) <= 1:
            d2 = np.linalg.norm([i - 2, j - 2, k - 2])
            expected[i, j, k] += 0.3 * (e - before[i, j, k]) * np.exp(-(d2**2) / (2 * e**2))
    np.testing.assert_allclose(g.values, expected, rtol=1e-12)
    assert changed == 27


def test_lambda_widens_and_eta_scales(along):
    fix, yhat = np.array([2.5, 2.5, 3.5]), np.array([2.5, 2.5, 2.5])  # e = 1 m
    wide = _map(along, neighborhood=2.0)
    assert wide.update(fix, yhat) == 125
    assert wide.values[0, 0, 0] != 0.2
    narrow = _map(along, neighborhood=0.0)
    narrow.update(fix, yhat)
    assert np.count_nonzero(narrow.values != 0.2) == 1
    full = _map(along, eta=1.0, neighborhood=0.0)
    full.update(fix, yhat)
    assert full.values[2, 2, 2] == pytest.approx(1.0), "eta = 1 jumps to the observed error"
    frozen = _map(along, eta=0.0)
    frozen.update(fix, yhat)
    assert np.all(frozen.values == 0.2)


def test_nac_leaves_g_untouched(along):
    g = _map(along, adaptive=False)
    assert g.update(np.array([3.0, 2.0, 2.0]), np.array([2.5, 2.5, 2.5])) == 0
    assert np.all(g.values == 0.2)


def _hermite_1d(f0: float, f1: float, t: float) -> float:
    return (2 * t**3 - 3 * t**2 + 1) * f0 + (-2 * t**3 + 3 * t**2) * f1


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_g_s_is_the_zero_slope_hermite_formula_along_each_axis(axis):
    profile = np.array([0.1, 0.9, 0.3, 2.0, 0.4])
    shape = [1, 1, 1]
    shape[axis] = 5
    values = np.broadcast_to(profile.reshape(shape), GRID.shape).copy()
    for i in range(4):
        for t in (0.0, 0.2, 0.5, 0.77):
            point = np.full(3, 1.3)
            point[axis] = i + 0.5 + t
            got = hermite_zero_slope(values, GRID, point)[0]
            assert got == pytest.approx(_hermite_1d(profile[i], profile[i + 1], t), abs=1e-12)


def test_g_s_interpolates_nodes_with_zero_slope_and_clamps_outside():
    rng = np.random.default_rng(3)
    values = rng.uniform(0.1, 3.0, GRID.shape)
    centres = GRID.centers().reshape(-1, 3)
    np.testing.assert_allclose(
        hermite_zero_slope(values, GRID, centres), values.reshape(-1), atol=1e-12
    )
    h = 1e-5
    for centre in centres[rng.choice(len(centres), 20, replace=False)]:
        for axis in range(3):
            step = np.zeros(3)
            step[axis] = h
            slope = (
                hermite_zero_slope(values, GRID, centre + step)[0]
                - hermite_zero_slope(values, GRID, centre - step)[0]
            ) / (2 * h)
            assert abs(slope) < 1e-3
    outside = np.array([[-3.0, 0.5, 0.5], [0.5, 9.0, 4.5]])
    np.testing.assert_allclose(
        hermite_zero_slope(values, GRID, outside), [values[0, 0, 0], values[0, 4, 4]]
    )


def test_casadi_g_s_equals_numpy_and_has_zero_gradient_at_nodes():
    rng = np.random.default_rng(8)
    grid = VoxelGrid.over(Box((-2.0, -3.0, 0.0), (4.0, 2.0, 4.0)), 1.0)
    values = rng.uniform(0.1, 3.0, grid.shape)
    x = ca.MX.sym("x", 3)
    expression = casadi_hermite(grid, x, ca.MX(ca.DM(values.ravel(order="F"))))
    g_s = ca.Function("g_s", [x], [expression])
    gradient = ca.Function("grad", [x], [ca.gradient(expression, x)])
    points = rng.uniform([-3, -4, -1], [5, 3, 5], (200, 3))
    got = np.array([float(g_s(p)) for p in points])
    np.testing.assert_allclose(got, hermite_zero_slope(values, grid, points), atol=1e-12)
    for centre in grid.centers().reshape(-1, 3)[::7]:
        np.testing.assert_allclose(np.array(gradient(centre)).ravel(), 0.0, atol=1e-9)


def test_the_inlined_g_s_computes_bit_for_bit_what_the_written_out_one_does():
    """The MPC builds its horizon's G_s terms from one inlined function: same values, same
    first and second derivatives, to the last bit, and no function call left in the graph."""
    rng = np.random.default_rng(10)
    grid = VoxelGrid(np.zeros(3), 1.0, (7, 6, 5))
    horizon = 4
    v = ca.MX.sym("v", 3, horizon)
    corner = ca.MX.sym("corner", 3)
    values = ca.MX.sym("values", grid.n_voxels)
    hermite = inlined_hermite(grid)
    written = sum(casadi_hermite(grid, v[:, u] - corner, values) for u in range(horizon))
    inlined = sum(hermite(v[:, u] - corner, values) for u in range(horizon))

    def derivatives(total):
        hessian = ca.hessian(total, ca.vec(v))[0]
        return ca.Function(
            "d", [ca.vec(v), corner, values], [total, ca.gradient(total, ca.vec(v)), hessian]
        )

    a, b = derivatives(written), derivatives(inlined)
    assert "hermite" not in str(inlined)  # inlined: the graph holds no call
    for _ in range(50):
        x = rng.uniform(-2.0, 9.0, 3 * horizon)
        shift = rng.uniform(-1.0, 1.0, 3)
        field = rng.uniform(0.0, 3.0, grid.n_voxels)
        for got, expected in zip(b(x, shift, field), a(x, shift, field), strict=True):
            assert np.array_equal(np.array(got), np.array(expected))


def test_casadi_g_s_hessian_has_the_mixed_terms_of_the_numpy_field():
    """IPOPT gets exact second derivatives: casadi's linear interpolant drops d2/dx dy."""
    rng = np.random.default_rng(9)
    grid = VoxelGrid.over(Box((0.0, 0.0, 0.0), (6.0, 6.0, 6.0)), 1.0)
    values = rng.uniform(0.0, 3.0, grid.shape)
    x = ca.MX.sym("x", 3)
    expression = casadi_hermite(grid, x, ca.MX(ca.DM(values.ravel(order="F"))))
    hessian = ca.Function("H", [x], [ca.hessian(expression, x)[0]])

    def field(p):
        return float(hermite_zero_slope(values, grid, p[None])[0])

    h = 1e-4
    steps = h * np.eye(3)
    for point in rng.uniform(0.7, 5.3, (10, 3)):
        numeric = np.array(
            [
                [
                    (
                        field(point + steps[i] + steps[j])
                        - field(point + steps[i] - steps[j])
                        - field(point - steps[i] + steps[j])
                        + field(point - steps[i] - steps[j])
                    )
                    / (4 * h * h)
                    for j in range(3)
                ]
                for i in range(3)
            ]
        )
        exact = np.array(hessian(point))
        np.testing.assert_allclose(exact, numeric, atol=1e-5)
        assert np.max(np.abs(exact - np.diag(np.diag(exact)))) > 1e-3  # mixed terms present
