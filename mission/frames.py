"""Frame conversions at the MAVLink boundary: ENU <-> NED and ENU <-> geodetic (WGS-84)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pymap3d

from mission.settings import GeodeticAnchor


def enu_to_ned(v: np.ndarray) -> np.ndarray:
    """(x_e, y_n, z_u) -> (north, east, down)."""
    v = np.asarray(v, dtype=float)
    return np.stack((v[..., 1], v[..., 0], -v[..., 2]), axis=-1)


def ned_to_enu(v: np.ndarray) -> np.ndarray:
    """(north, east, down) -> (x_e, y_n, z_u)."""
    v = np.asarray(v, dtype=float)
    return np.stack((v[..., 1], v[..., 0], -v[..., 2]), axis=-1)


@dataclass(frozen=True)
class GeodeticFrame:
    """The local ENU frame anchored at a geodetic origin."""

    anchor: GeodeticAnchor

    def to_geodetic(self, enu: np.ndarray) -> tuple[float, float, float]:
        """ENU point (m) -> (lat deg, lon deg, ellipsoidal alt m)."""
        e, n, u = (float(c) for c in np.asarray(enu, dtype=float).reshape(3))
        a = self.anchor
        lat, lon, alt = pymap3d.enu2geodetic(e, n, u, a.lat_deg, a.lon_deg, a.alt_m)
        return float(lat), float(lon), float(alt)

    def to_enu(self, lat_deg: float, lon_deg: float, alt_m: float) -> np.ndarray:
        """(lat deg, lon deg, ellipsoidal alt m) -> ENU point (m)."""
        a = self.anchor
        e, n, u = pymap3d.geodetic2enu(lat_deg, lon_deg, alt_m, a.lat_deg, a.lon_deg, a.alt_m)
        return np.array([float(e), float(n), float(u)])

    def to_degE7(self, enu: np.ndarray) -> tuple[int, int, float]:
        """ENU point -> (lat 1e-7 deg, lon 1e-7 deg, alt m), as MAVLink's *_INT fields hold it."""
        lat, lon, alt = self.to_geodetic(enu)
        return round(lat * 1e7), round(lon * 1e7), alt

    def from_degE7(self, lat_e7: int, lon_e7: int, alt_m: float) -> np.ndarray:
        """(lat 1e-7 deg, lon 1e-7 deg, alt m) -> ENU point."""
        return self.to_enu(lat_e7 / 1e7, lon_e7 / 1e7, alt_m)
