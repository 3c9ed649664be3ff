"""10,000 random and mutated datagrams at a vehicle: it survives and still does its job."""

from __future__ import annotations

import socket
import time

import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.link.mission_items import MissionItem
from tests.fuzzing import hostile_datagrams
from tests.mav_client import MavClient
from tests.mission_download import DownloadingClient
from tests.processes import vehicle_process

pytestmark = pytest.mark.slow  # every test here starts processes


def test_vehicle_survives_fuzzing_and_still_takes_a_mission():
    datagrams = hostile_datagrams()
    assert len(datagrams) >= 10_000
    with vehicle_process("support-1") as vehicle:  # lockstep: fuzzed clock ticks included
        fuzzer = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        for i, datagram in enumerate(datagrams):
            fuzzer.sendto(datagram, vehicle.address)
            if i % 200 == 199:
                time.sleep(0.005)
        fuzzer.close()
        time.sleep(0.5)
        assert vehicle.process.poll() is None, "the vehicle died"
        client = MavClient(vehicle.address)
        items = [
            MissionItem(i, 3, 16, 0, 1, 0.0, 0.1, 0.0, 0.0, 351500000 + i, 1369600000, 7.0)
            for i in range(6)
        ]
        mission = DownloadingClient(client.queue, vehicle.address, 2, timeout_s=2.0)
        assert mission.upload(items) == mavlink2.MAV_MISSION_ACCEPTED
        assert [i.x for i in mission.download()] == [i.x for i in items]
        client.close()
        summary = vehicle.stop()
    assert vehicle.process.returncode == 0
    bad = int(summary.split("bad ")[1].split(" datagrams")[0])
    assert bad >= 3000, summary
    assert "Traceback" not in summary
