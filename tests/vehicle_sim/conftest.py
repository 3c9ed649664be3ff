"""What the vehicle tests share: a MAVLink client of the module's own ``vehicle`` process."""

from __future__ import annotations

import pytest

from tests.mav_client import MavClient


@pytest.fixture
def client(vehicle):
    """A client of the module's ``vehicle`` fixture, closed after the test."""
    mav = MavClient(vehicle.address)
    yield mav
    mav.close()
