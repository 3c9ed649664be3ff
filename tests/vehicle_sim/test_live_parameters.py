"""A parameter set live changes what the vehicle does (in-process vehicles): the failsafe trips
after FS_GCS_TIMEOUT as set, not as the scenario had it."""

from __future__ import annotations

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.link.vehicle_identity import VehicleIdentity
from vehicle_sim import modes
from vehicle_sim.vehicle import Vehicle


def _failsafe_after_s(world, timeout_s: float | None) -> float:
    """Simulated seconds from the last setpoint to the failsafe's STATUSTEXT."""
    sent: list = []
    home = np.array([0.0, -10.0, 7.0])
    vehicle = Vehicle(
        VehicleIdentity.parse("support-1"), world.scenario, world, home, 0, sent.append
    )
    if timeout_s is not None:
        vehicle.params.handle(
            mavlink2.MAVLink_param_set_message(
                2, 1, b"FS_GCS_TIMEOUT", timeout_s, mavlink2.MAV_PARAM_TYPE_REAL32
            )
        )
    vehicle.change_mode(modes.GUIDED)
    vehicle.arm(True)
    sent.clear()
    while vehicle.sim_time_s < 60.0:
        vehicle.step()
        if any(m.get_type() == "STATUSTEXT" and "Failsafe" in m.text for m in sent):
            return vehicle.sim_time_s
    raise AssertionError("no failsafe within 60 s")


def test_the_failsafe_trips_after_the_timeout_set_live(along_world):
    default = along_world.scenario.vehicle.failsafe_s
    assert _failsafe_after_s(along_world, None) == default + along_world.scenario.control.t_cont_s
    assert _failsafe_after_s(along_world, 2 * default) > 2 * default - 1e-9
