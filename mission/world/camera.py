"""Relative observation of the work UAV by a support UAV's camera (paper 3.1.2)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mission.config.settings import CameraSettings
from mission.world.structure import Structure


def spherical(z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Distance d, elevation phi = asin(z_z / d) and azimuth theta = atan2(z_y, z_x) of z."""
    z = np.asarray(z, dtype=float)
    d = np.linalg.norm(z, axis=-1)
    phi = np.arcsin(np.clip(z[..., 2] / np.where(d > 0, d, 1.0), -1.0, 1.0))
    theta = np.arctan2(z[..., 1], z[..., 0])
    return d, phi, theta


def spherical_jacobian(d: np.ndarray, phi: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Jacobian d(x, y, z)/d(d, phi, theta) of d (cos phi cos theta, cos phi sin theta, sin phi)."""
    d, phi, theta = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (d, phi, theta)))
    cp, sp, ct, st = np.cos(phi), np.sin(phi), np.cos(theta), np.sin(theta)
    jac = np.empty((*d.shape, 3, 3))
    jac[..., :, 0] = np.stack((cp * ct, cp * st, sp), axis=-1)
    jac[..., :, 1] = np.stack((-d * sp * ct, -d * sp * st, d * cp), axis=-1)
    jac[..., :, 2] = np.stack((-d * cp * st, d * cp * ct, np.zeros_like(d)), axis=-1)
    return jac


@dataclass(frozen=True)
class Observation:
    """What a camera reports: valid or not, and the measured relative vector r (ENU)."""

    valid: bool
    relative_m: np.ndarray | None
    distance_m: float


class CameraModel:
    """sigma_d quadratic in distance, constant angle sigmas, Sigma_r through the Jacobian."""

    def __init__(self, settings: CameraSettings, structure: Structure | None = None) -> None:
        self.settings = settings
        self.structure = structure
        self._sigma_phi = np.radians(settings.sigma_elevation_deg)
        self._sigma_theta = np.radians(settings.sigma_azimuth_deg)

    def sigma_d(self, d: np.ndarray) -> np.ndarray:
        """Distance standard deviation a2 d^2 + a1 d + a0."""
        s = self.settings
        d = np.asarray(d, dtype=float)
        return s.sigma_d_a2_per_m * d**2 + s.sigma_d_a1 * d + s.sigma_d_a0_m

    def sigmas(self, z: np.ndarray) -> np.ndarray:
        """(..., 3) standard deviations of (d, phi, theta) at relative vector z."""
        d, _, _ = spherical(z)
        return np.stack(
            (self.sigma_d(d), np.full_like(d, self._sigma_phi), np.full_like(d, self._sigma_theta)),
            axis=-1,
        )

    def covariance(self, z: np.ndarray) -> np.ndarray:
        """Sigma_r(z) = J diag(sigma_d^2, sigma_phi^2, sigma_theta^2) J^T (..., 3, 3)."""
        jac = spherical_jacobian(*spherical(z))
        variances = self.sigmas(z) ** 2
        return np.einsum("...ik,...k,...jk->...ij", jac, variances, jac)

    def sample(self, z: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """r = z + N(0, Sigma_r(z)), drawn as J (sigma * n): exact even if Sigma_r is singular."""
        z = np.asarray(z, dtype=float)
        jac = spherical_jacobian(*spherical(z))
        scaled = self.sigmas(z) * rng.standard_normal(z.shape)
        return z + np.einsum("...ij,...j->...i", jac, scaled)

    def observable(self, observer: np.ndarray, target: np.ndarray) -> np.ndarray:
        """True where the target is within range and the sight line misses the structure."""
        observer = np.atleast_2d(np.asarray(observer, dtype=float))
        target = np.atleast_2d(np.asarray(target, dtype=float))
        offset = target - observer
        distance = np.sqrt(np.add.reduce(offset * offset, axis=1))  # np.linalg.norm's sum
        in_range = (distance <= self.settings.range_m) & (distance > 0)
        if self.structure is None:
            return in_range
        if in_range.all():  # the usual case: every sight line is cast
            return ~self.structure.segments_blocked(observer, target)
        clear = np.zeros_like(in_range)
        if np.any(in_range):
            observer_b, target_b = np.broadcast_arrays(observer, target)
            clear[in_range] = ~self.structure.segments_blocked(
                observer_b[in_range], target_b[in_range]
            )
        return in_range & clear

    def observe(
        self,
        observer: np.ndarray,
        target: np.ndarray,
        rng: np.random.Generator,
        range_m: float | None = None,
        noise_scale: float = 1.0,
    ) -> Observation:
        """One observation of ``target`` from ``observer`` (true positions); ``range_m`` and
        ``noise_scale`` (times every sigma) where the camera is not as the settings say.

        The single-vector path of :meth:`observable` and :meth:`sample`, in scalar arithmetic
        because the vehicles call it every step.
        """
        reach = self.settings.range_m if range_m is None else range_m
        observer = np.asarray(observer, dtype=float).reshape(3)
        target = np.asarray(target, dtype=float).reshape(3)
        z = target - observer
        d = math.sqrt(float(z @ z))
        if not 0 < d <= reach:
            return Observation(False, None, d)
        if self.structure is not None and self.structure.segment_blocked(observer, target):
            return Observation(False, None, d)
        phi = math.asin(max(-1.0, min(1.0, z[2] / d)))
        theta = math.atan2(z[1], z[0])
        cp, sp, ct, st = math.cos(phi), math.sin(phi), math.cos(theta), math.sin(theta)
        jacobian = np.array(
            [
                [cp * ct, -d * sp * ct, -d * cp * st],
                [cp * st, -d * sp * st, d * cp * ct],
                [sp, d * cp, 0.0],
            ]
        )
        sigma = np.array([float(self.sigma_d(d)), self._sigma_phi, self._sigma_theta])
        if noise_scale != 1.0:
            sigma = noise_scale * sigma
        return Observation(True, z + jacobian @ (sigma * rng.standard_normal(3)), d)
