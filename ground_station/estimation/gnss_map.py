"""The GNSS-localizability map G (paper 4.1) and its smoothed field G_s (4.2).

G holds one sigma per voxel, initialised from sigma_0 (what the ground station can predict from
the structure and the sky) and pulled toward the observed GNSS error |p_n - yhat_n| by a Gaussian
kernel around the voxel of yhat_n. G_s is tensor-product cubic Hermite interpolation with zero
slope at the voxel centres, computed exactly as multilinear interpolation at the warped index
i + s(t), s(t) = 3t^2 - 2t^3; outside the grid it takes the nearest border value.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import casadi as ca
import numpy as np

from ground_station.estimation.fusion import SupportMeasurement
from mission.config.settings import MapSettings
from mission.world.grid import VoxelGrid

Change = tuple[tuple[np.ndarray, ...], np.ndarray]  # voxel indices, what was added to each


class LocalizabilityMap:
    """G over a voxel grid; ``adaptive=False`` (the NAC baseline) switches the update off."""

    def __init__(
        self, grid: VoxelGrid, sigma0: np.ndarray, settings: MapSettings, adaptive: bool = True
    ) -> None:
        self.grid = grid
        self.settings = settings
        self.adaptive = adaptive
        self.values = np.array(sigma0, dtype=float).reshape(grid.shape)
        self.initial = self.values.copy()
        reach = int(np.floor(settings.neighborhood + 1e-9))
        self._offsets = np.array(list(itertools.product(range(-reach, reach + 1), repeat=3)))
        self._d2 = grid.voxel_m * np.linalg.norm(self._offsets, axis=1)

    def update(self, fix: np.ndarray, yhat: np.ndarray) -> int:
        """sigma <- sigma + eta (e - sigma) exp(-D2^2 / (2 e^2)) around yhat's voxel.

        Returns how many voxels changed (0 for NAC, or when yhat lies outside the grid).
        """
        return self.update_recorded(fix, yhat)[0]

    def update_recorded(self, fix: np.ndarray, yhat: np.ndarray) -> tuple[int, Change | None]:
        """:meth:`update`, and what it changed (the voxels and what was added to each), for
        :meth:`take_back`; None where nothing changed."""
        if not self.adaptive:
            return 0, None
        lo = self.grid.origin_m
        hi = lo + self.grid.voxel_m * np.array(self.grid.shape)
        if np.any(yhat < lo) or np.any(yhat >= hi):
            return 0, None
        error = float(np.linalg.norm(np.asarray(fix) - np.asarray(yhat)))
        centre = self.grid.index_of(np.asarray(yhat)[None])[0]
        index = centre + self._offsets
        valid = np.all((index >= 0) & (index < np.array(self.grid.shape)), axis=1)
        index, d2 = index[valid], self._d2[valid]
        if error > 0:
            weight = np.exp(-(d2**2) / (2 * error**2))
        else:
            weight = (d2 == 0).astype(float)
        cells = tuple(index.T)
        added = self.settings.eta * (error - self.values[cells]) * weight
        self.values[cells] += added
        return int(np.count_nonzero(weight)), (cells, added)

    def take_back(self, changes: Sequence[Change]) -> None:
        """Undo updates (latest first): what a support that turned out to carry its bias
        with it (a receiver at fault, not a place) taught G. Updates others made to the same
        voxels meanwhile stay, as they were computed (on values that held this support's)."""
        for cells, added in reversed(changes):
            self.values[cells] -= added

    def smoothed(self, points: np.ndarray) -> np.ndarray:
        """G_s at points (N, 3), in numpy."""
        return hermite_zero_slope(self.values, self.grid, points)

    def smoothed_with_initial(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """G_s now and as it started (sigma_0's), at points (N, 3)."""
        now, initial = hermite_zero_slope_of((self.values, self.initial), self.grid, points)
        return now, initial


def learn(
    g: LocalizabilityMap, measurements: Sequence[SupportMeasurement], yhat: dict[str, np.ndarray]
) -> int:
    """Step 4 of the control cycle: G updated around each support's yhat_n with its GNSS error
    |p_n - yhat_n|, for the supports with both a fix and an observation (without one, yhat_n is
    p_n and says nothing about the error); returns how many voxel updates were made."""
    updated = 0
    for support in measurements:
        if support.fix_m is not None and support.relative_m is not None:
            updated += g.update(support.fix_m, yhat[support.name])
    return updated


def warped_index(u: np.ndarray | ca.MX | ca.SX, upper: np.ndarray) -> np.ndarray | ca.MX | ca.SX:
    """i + s(t) for fractional voxel index u clipped to [0, upper], s(t) = 3t^2 - 2t^3."""
    if isinstance(u, ca.MX | ca.SX):
        clipped = ca.fmin(ca.fmax(u, 0), upper)
        base = ca.fmin(ca.floor(clipped), ca.fmax(upper - 1, 0))
        t = clipped - base
        return base + 3 * t**2 - 2 * t**3
    clipped = np.clip(u, 0, upper)
    base = np.minimum(np.floor(clipped), np.maximum(upper - 1, 0))
    t = clipped - base
    return base + 3 * t**2 - 2 * t**3


_CORNERS = np.array(list(itertools.product((0, 1), repeat=3)))
_CORNER_IS_HIGH = _CORNERS == 1


def hermite_zero_slope(values: np.ndarray, grid: VoxelGrid, points: np.ndarray) -> np.ndarray:
    """Zero-slope cubic Hermite interpolation of voxel values at points (numpy)."""
    return hermite_zero_slope_of((values,), grid, points)[0]


def hermite_zero_slope_of(
    maps: Sequence[np.ndarray], grid: VoxelGrid, points: np.ndarray
) -> list[np.ndarray]:
    """:func:`hermite_zero_slope` of several maps over the same grid at the same points, the
    corners and their weights found once (each map's values as it alone gives them)."""
    points = np.atleast_2d(np.asarray(points, dtype=float))
    upper, base_cap, last = grid.index_limits
    u = (points - grid.origin_m) / grid.voxel_m - 0.5
    w = warped_index(u, upper)
    base = np.minimum(np.floor(w).astype(int), base_cap)
    frac = w - base
    # the eight corners at once: (N, 8, 3) indices and per-axis weights
    index = np.minimum(base[:, None, :] + _CORNERS, last)
    factors = np.where(_CORNER_IS_HIGH, frac[:, None, :], 1 - frac[:, None, :])
    weight = factors[..., 0] * factors[..., 1] * factors[..., 2]
    corners = (index[..., 0], index[..., 1], index[..., 2])
    results = []
    for values in maps:
        terms = weight * values[corners]
        result = terms[:, 0].copy()
        for corner in range(1, len(_CORNERS)):  # summed in corner order, as the loop it replaced
            result += terms[:, corner]
        results.append(result)
    return results


def casadi_hermite(grid: VoxelGrid, x: ca.MX, values: ca.MX) -> ca.MX:
    """G_s at x (3) for voxel values (nx*ny*nz, first axis fastest), as a casadi expression.

    The eight corner values are gathered by index and weighted as in
    :func:`hermite_zero_slope`, so every derivative is exact. casadi's parametric linear
    interpolant computes the same values, but its second derivatives lack the mixed terms
    (d2/dx dy = 0, which cost IPOPT extra iterations and some failures), and its derivatives,
    like those of any Function call, carry a dense seed for every value. Written inline, the
    derivatives touch the eight gathered values only.
    """
    shape = np.array(grid.shape)
    u = (x - ca.DM(grid.origin_m)) / grid.voxel_m - 0.5
    bases, fracs = [], []
    for a in range(3):
        warped = warped_index(u[a], float(shape[a] - 1))
        base = ca.fmin(ca.floor(warped), float(max(shape[a] - 2, 0)))
        bases.append(base)
        fracs.append(warped - base)
    strides = np.concatenate([[1], np.cumprod(shape[:-1])]).astype(float)
    total = 0
    for corner in _CORNERS:  # summed in corner order with weights f0 f1 f2, as in numpy
        index = 0
        weight = 1
        for a in range(3):
            index += strides[a] * ca.fmin(bases[a] + float(corner[a]), float(shape[a] - 1))
            weight *= fracs[a] if corner[a] else 1 - fracs[a]
        total += weight * values[index]
    return total


def inlined_hermite(grid: VoxelGrid) -> ca.Function:
    """:func:`casadi_hermite` as a function of (x, values) that is inlined where it is called:
    the same expression, built once rather than once per call (a horizon's terms build 5x
    faster, and share their constants)."""
    x = ca.MX.sym("x", 3)
    values = ca.MX.sym("values", grid.n_voxels)
    return ca.Function(
        "hermite", [x, values], [casadi_hermite(grid, x, values)], {"always_inline": True}
    )
