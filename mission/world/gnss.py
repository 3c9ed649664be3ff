"""GNSS of a support UAV (paper 3.1.1): visibility, dilution of precision, noisy fixes.

One receiver-clock unknown per constellation that has a visible satellite, so GPS+GLONASS
gives the 5-column geometry matrix of docs/model.md, "GNSS of a support UAV"; a
constellation with no visible satellite contributes no column (a receiver does not solve for
a clock it cannot observe).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from mission.config.settings import GnssSettings
from mission.world.sky import Sky
from mission.world.structure import Structure

_CHUNK = 20_000
_MIN_EIGENVALUE = 1e-9
_MAX_REMEMBERED_MASKS = 4096  # visibility masks whose fix geometry a model keeps
_MEMO_MAX_POINTS = 16  # larger batches (maps) are computed once per distinct mask


@dataclass(frozen=True)
class GnssGeometry:
    """Satellite geometry at N points: which satellites are visible and cov_geom where fixed."""

    visible: np.ndarray
    has_fix: np.ndarray
    cov_geom: np.ndarray

    @property
    def n_visible(self) -> np.ndarray:
        """Number of visible satellites at each point."""
        return self.visible.sum(axis=1)

    @property
    def pdop(self) -> np.ndarray:
        """Position dilution of precision (NaN without a fix)."""
        return np.sqrt(np.trace(self.cov_geom, axis1=1, axis2=2))

    @property
    def hdop(self) -> np.ndarray:
        """Horizontal dilution of precision (NaN without a fix)."""
        return np.sqrt(self.cov_geom[:, 0, 0] + self.cov_geom[:, 1, 1])

    @property
    def vdop(self) -> np.ndarray:
        """Vertical dilution of precision (NaN without a fix)."""
        return np.sqrt(self.cov_geom[:, 2, 2])


class GnssModel:
    """Sky + structure + ranging noise: everything needed for Sigma_GNSS and sampled fixes."""

    def __init__(self, sky: Sky, structure: Structure, settings: GnssSettings) -> None:
        self.sky = sky
        self.structure = structure
        self.settings = settings
        self._directions = sky.directions_enu
        self._rows = _geometry_rows(
            self._directions, sky.constellation_index(), len(sky.constellations)
        )
        self._fix_geometry_by_mask: dict[bytes, tuple[np.ndarray | None, np.ndarray | None]] = {}
        self._geometry_by_mask: dict[bytes, tuple[bool, np.ndarray]] = {}

    @cached_property
    def _above_mask(self) -> tuple[np.ndarray, np.ndarray]:
        """The satellites above the elevation mask and their directions (the sky is fixed)."""
        masked_in = np.flatnonzero(self.sky.above_mask)
        return masked_in, self._directions[masked_in]

    @property
    def geometry_rows(self) -> np.ndarray:
        """(S, 3 + constellations): each satellite's row of H, [-e^T, its clock's one-hot]."""
        return self._rows

    def visibility(self, points: np.ndarray) -> np.ndarray:
        """(N, S) True where the satellite is above the mask and its ray misses the structure."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        n_points, n_sats = len(points), len(self.sky.sv)
        visible = np.zeros((n_points, n_sats), dtype=bool)
        masked_in, above = self._above_mask
        if len(masked_in) == 0 or n_points == 0:
            return visible
        origins = np.repeat(points, len(masked_in), axis=0)
        directions = above if n_points == 1 else np.tile(above, (n_points, 1))
        blocked = self.structure.rays_blocked(origins, directions).reshape(n_points, -1)
        visible[:, masked_in] = ~blocked
        return visible

    def geometry(self, points: np.ndarray) -> GnssGeometry:
        """Visibility and geometric covariance cov_geom (top-left 3x3 of (H^T H)^-1)."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        parts = [
            self._geometry_chunk(points[start : start + _CHUNK])
            for start in range(0, max(len(points), 1), _CHUNK)
        ]
        return GnssGeometry(
            visible=np.concatenate([p[0] for p in parts]),
            has_fix=np.concatenate([p[1] for p in parts]),
            cov_geom=np.concatenate([p[2] for p in parts]),
        )

    def geometry_from_visibility(self, visible: np.ndarray) -> GnssGeometry:
        """cov_geom for given visibility masks (N, S), without ray casting.

        Every mask is computed once (a row's numbers do not depend on the rows computed with
        it, tested bit for bit): a few points at a time (a cycle's fixes) are looked up in a
        memory of masks; a map's points are grouped by mask (40,000 voxels of the bridge
        share ~300 masks).
        """
        visible = np.asarray(visible, dtype=bool)
        if len(visible) > _MEMO_MAX_POINTS:
            has_fix, cov = self._covariance_per_distinct_mask(visible)
            return GnssGeometry(visible=visible, has_fix=has_fix, cov_geom=cov)
        keys = [row.tobytes() for row in visible]
        if len(self._geometry_by_mask) + len(keys) > _MAX_REMEMBERED_MASKS:
            self._geometry_by_mask.clear()
        missing = {k: i for i, k in enumerate(keys) if k not in self._geometry_by_mask}
        if missing:
            rows = list(missing.values())
            has_fix, cov = self._covariance(visible[rows])
            for j, key in enumerate(missing):
                self._geometry_by_mask[key] = (bool(has_fix[j]), cov[j])
        known = [self._geometry_by_mask[k] for k in keys]
        return GnssGeometry(
            visible=visible,
            has_fix=np.array([fix for fix, _ in known], dtype=bool),
            cov_geom=np.array([cov for _, cov in known]).reshape(len(keys), 3, 3),
        )

    def _covariance_per_distinct_mask(self, visible: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        packed = np.packbits(visible, axis=1)
        keys = np.ascontiguousarray(packed).view(np.dtype((np.void, packed.shape[1]))).ravel()
        _, first, index = np.unique(keys, return_index=True, return_inverse=True)
        has_fix, cov = self._covariance(visible[first])
        index = index.reshape(-1)
        return has_fix[index], cov[index]

    def _covariance(self, visible: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return _covariance_from_visibility(visible, self._rows, self.sky.constellation_index())

    def _geometry_chunk(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        geometry = self.geometry_from_visibility(self.visibility(points))
        return geometry.visible, geometry.has_fix, geometry.cov_geom

    def sigma_gnss(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(has_fix (N,), Sigma_GNSS (N, 3, 3)) with NaN where there is no fix."""
        geometry = self.geometry(points)
        return geometry.has_fix, self.settings.sigma_uere_m**2 * geometry.cov_geom

    def has_fix(self, points: np.ndarray) -> np.ndarray:
        """(N,) whether a receiver at each point has a 3-D fix."""
        return self.geometry_from_visibility(self.visibility(points)).has_fix

    def sigma0(self, points: np.ndarray) -> np.ndarray:
        """sqrt(tr Sigma_GNSS) = sigma_UERE * PDOP at each point (NaN without a fix)."""
        return self.settings.sigma_uere_m * self.geometry(points).pdop

    def sample_fix(
        self,
        point: np.ndarray,
        rng: np.random.Generator,
        offset_m: np.ndarray | None = None,
        sigma_uere_m: float | None = None,
    ) -> GnssFix:
        """One fix at true position ``point``: truth + N(0, Sigma_GNSS) + multipath offset
        (``sigma_uere_m``: the receiver's, where it is not the settings')."""
        point = np.asarray(point, dtype=float).reshape(3)
        visible = self.visibility(point[None])[0]
        n_visible = int(visible.sum())
        cov_geom, factor = self._fix_geometry(visible)
        sigma = self.settings.sigma_uere_m if sigma_uere_m is None else sigma_uere_m
        return noisy_fix(point, cov_geom, factor, n_visible, rng, sigma, offset_m)

    def _fix_geometry(self, visible: np.ndarray) -> tuple[np.ndarray | None, np.ndarray | None]:
        """cov_geom and its Cholesky factor for a visibility mask (None without a fix),
        remembered per mask: a vehicle sees the same few sets of satellites step after step."""
        key = visible.tobytes()
        known = self._fix_geometry_by_mask.get(key)
        if known is None:
            cov_geom = _single_point_cov_geom(
                self._rows[visible], self.sky.constellation_index()[visible]
            )
            factor = cholesky_or_none(cov_geom) if cov_geom is not None else None
            if len(self._fix_geometry_by_mask) >= _MAX_REMEMBERED_MASKS:
                self._fix_geometry_by_mask.clear()
            known = self._fix_geometry_by_mask[key] = (cov_geom, factor)
        return known


@dataclass(frozen=True)
class GnssFix:
    """A receiver's output: position (None without fix) and the accuracy it believes in."""

    has_fix: bool
    position_m: np.ndarray | None
    covariance_m2: np.ndarray | None
    n_visible: int
    hdop: float | None
    vdop: float | None
    solution: str = "rtk-fixed"  # or "rtk-float" / "code" (multipath from geometry)


def cholesky_or_none(matrix: np.ndarray) -> np.ndarray | None:
    """Lower Cholesky factor, or None when the matrix is not positive definite (no fix)."""
    try:
        factor = np.linalg.cholesky(matrix)
    except np.linalg.LinAlgError:
        return None
    return factor if np.all(np.isfinite(factor)) else None


def noisy_fix(
    solved: np.ndarray,
    cov_geom: np.ndarray | None,
    factor: np.ndarray | None,
    n_used: int,
    rng: np.random.Generator,
    sigma: float,
    offset_m: np.ndarray | None = None,
    solution: str = "rtk-fixed",
) -> GnssFix:
    """A receiver's fix: ``solved`` (the truth, or the truth and the geometry's bias) +
    sigma ``factor`` z (z three standard normals drawn from ``rng``) + ``offset_m`` (a
    zone's); no fix (and no draw) without a geometry. Accuracy from ``cov_geom`` alone."""
    if cov_geom is None or factor is None:
        return GnssFix(False, None, None, n_used, None, None)
    noise = sigma * (factor @ rng.standard_normal(3))
    offset = np.zeros(3) if offset_m is None else np.asarray(offset_m, dtype=float)
    return GnssFix(
        True,
        solved + noise + offset,
        sigma**2 * cov_geom,
        n_used,
        float(np.sqrt(cov_geom[0, 0] + cov_geom[1, 1])),
        float(np.sqrt(cov_geom[2, 2])),
        solution,
    )


def least_squares_fix(
    rows: np.ndarray, system: np.ndarray, weight: np.ndarray, error: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The weighted least-squares fix of N receivers from pseudorange errors ``error`` (N, S)
    with ``weight`` (N, S; 0: not used): (has_fix (N,), position error (N, 3), cov_geom
    (N, 3, 3)), NaN without a fix. ``rows``: H's rows (S, 3 + C), [-e^T, one-hot clock];
    ``system``: each satellite's constellation (S,). A clock no used satellite observes is no
    unknown (a unit diagonal decouples its column); no fix from fewer satellites than
    unknowns or a singular geometry."""
    used = weight > 0
    n_systems = rows.shape[1] - 3
    normal = np.einsum("ns,si,sj->nij", weight, rows, rows)
    per_system = np.stack([used[:, system == k].sum(axis=1) for k in range(n_systems)], axis=1)
    unused = per_system == 0
    for k in range(n_systems):
        normal[unused[:, k], 3 + k, 3 + k] = 1.0
    unknowns = 3 + (~unused).sum(axis=1)
    enough = used.sum(axis=1) >= unknowns
    has_fix = enough & (np.linalg.eigvalsh(normal)[:, 0] > _MIN_EIGENVALUE)
    position_error = np.full((len(used), 3), np.nan)
    cov = np.full((len(used), 3, 3), np.nan)
    if np.any(has_fix):
        inverse = np.linalg.inv(normal[has_fix])
        rhs = np.einsum("ns,si,ns->ni", weight[has_fix], rows, error[has_fix])
        position_error[has_fix] = np.einsum("nij,nj->ni", inverse, rhs)[:, :3]
        cov[has_fix] = inverse[:, :3, :3]
    return has_fix, position_error, cov


def _geometry_rows(directions: np.ndarray, system: np.ndarray, n_systems: int) -> np.ndarray:
    """Rows of H for every satellite: [-e^T, one-hot receiver clock of its constellation]."""
    clock = np.zeros((len(directions), n_systems))
    clock[np.arange(len(directions)), system] = 1.0
    return np.hstack((-directions, clock))


def _covariance_from_visibility(
    visible: np.ndarray, rows: np.ndarray, system: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    visible = np.asarray(visible, dtype=bool)
    weight = visible.astype(float)
    has_fix, _, cov = least_squares_fix(rows, system, weight, np.zeros_like(weight))
    return has_fix, cov


def _single_point_cov_geom(rows: np.ndarray, system: np.ndarray) -> np.ndarray | None:
    """cov_geom from the visible satellites' rows at one point, or None without a fix.

    Same rule as the batched path: only the clocks of constellations in view are unknowns.
    """
    # the constellations in view, ascending (np.unique would import numpy.ma: ~30 ms of CPU
    # in every vehicle at its first fix)
    used = np.flatnonzero(np.bincount(system))
    h = np.hstack((rows[:, :3], rows[:, 3 + used]))
    if len(h) < h.shape[1]:
        return None
    normal = h.T @ h
    if np.linalg.eigvalsh(normal)[0] <= _MIN_EIGENVALUE:  # the batched path's rule
        return None
    return np.linalg.inv(normal)[:3, :3]
