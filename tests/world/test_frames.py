"""Frame conversions against pymap3d (an independent implementation)."""

from __future__ import annotations

import numpy as np
import pymap3d
import pytest

from mission.config.settings import GeodeticAnchor
from mission.world.frames import GeodeticFrame, ecef_to_geodetic, enu_to_ned, ned_to_enu


@pytest.mark.parametrize(
    "anchor", [(35.15, 136.96, 0.0), (-33.9, 151.2, 120.0), (64.1, -21.9, 5.0)]
)
def test_enu_to_geodetic_matches_pymap3d(anchor):
    frame = GeodeticFrame(GeodeticAnchor(*anchor))
    rng = np.random.default_rng(0)
    for enu in rng.uniform(-500, 500, (50, 3)):
        lat, lon, alt = frame.to_geodetic(enu)
        expected = pymap3d.enu2geodetic(*enu, *anchor)
        assert lat == pytest.approx(expected[0], abs=1e-10)
        assert lon == pytest.approx(expected[1], abs=1e-10)
        assert alt == pytest.approx(expected[2], abs=1e-6)
        np.testing.assert_allclose(frame.to_enu(lat, lon, alt), enu, atol=1e-6)


def test_ecef_to_geodetic_at_the_poles_and_equator():
    for lat, lon, alt in [(89.9999, 10.0, 100.0), (0.0, -45.0, 0.0), (-60.0, 179.9, 3000.0)]:
        ecef = pymap3d.geodetic2ecef(lat, lon, alt)
        got = ecef_to_geodetic(*ecef)
        assert got == pytest.approx((lat, lon, alt), abs=1e-7)


def test_enu_ned_swap():
    v = np.array([1.0, 2.0, 3.0])
    np.testing.assert_array_equal(enu_to_ned(v), [2.0, 1.0, -3.0])
    np.testing.assert_array_equal(ned_to_enu(enu_to_ned(v)), v)
