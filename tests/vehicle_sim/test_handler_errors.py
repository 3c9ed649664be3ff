"""A message whose handling raises never kills the vehicle: it is counted, and the first of
each kind is logged with its traceback (a counter alone says nothing of where)."""

from __future__ import annotations

import os
from types import SimpleNamespace

os.environ.setdefault("MAVLINK20", "1")
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from vehicle_sim.dynamics.clock import StepClock
from vehicle_sim.process.pacing import ClockSettings
from vehicle_sim.server import VehicleServer


class _Breaking:
    """A vehicle whose handler fails on every message."""

    identity = SimpleNamespace(system_id=2)
    scenario = SimpleNamespace(vehicle=SimpleNamespace(lockstep_timeout_wall_s=2.0))

    def __init__(self) -> None:
        self.clock = StepClock(0.1, 0.0)
        self.counters = SimpleNamespace(rejected=[], reject=lambda kind: self.counted(kind))

    def counted(self, kind: str) -> None:
        self.counters.rejected.append(kind)

    def handle(self, message, now: float) -> None:
        raise KeyError("the missing field")


def test_a_handler_error_is_counted_and_its_first_of_a_kind_logged(capsys):
    server = VehicleServer(SimpleNamespace(), [], ClockSettings(lockstep=True))
    vehicle = _Breaking()
    server.attach(vehicle)
    link = mavlink2.MAVLink(None, srcSystem=255, srcComponent=190)
    for n in range(3):
        message = link.param_request_list_encode(2, 1)
        message.pack(link)
        server._on_message(message, ("127.0.0.1", 9000), float(n))
    assert vehicle.counters.rejected == ["handler error KeyError"] * 3
    err = capsys.readouterr().err
    assert err.count("Traceback") == 1 and "PARAM_REQUEST_LIST raised" in err
    assert "KeyError: 'the missing field'" in err
