"""The fast tlog reader against pymavlink's own, on a hand-made tlog."""

from __future__ import annotations

import os
import struct
from pathlib import Path

import numpy as np
import pytest

os.environ.setdefault("MAVLINK20", "1")
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.analysis.metrics import read_tlog
from mission.config.scenario import load_scenario
from tests.tlog_reference import read_tlog_with_mavutil


def _packet(system: int, message) -> bytes:
    mav = mavlink2.MAVLink(None, srcSystem=system, srcComponent=1)
    return bytes(message.pack(mav))


def _sim_state(step: int):
    zeros = dict.fromkeys(
        ["q1", "q2", "q3", "q4", "roll", "pitch", "yaw", "xacc", "yacc", "zacc", "xgyro"]
        + ["ygyro", "zgyro", "lat", "lon", "std_dev_horz", "std_dev_vert", "vn", "ve", "vd"],
        0.0,
    )
    return mavlink2.MAVLink_sim_state_message(
        **zeros, alt=10.0, lat_int=351_000_000 + step, lon_int=1_369_000_000
    )


def _records(epoch: float) -> list[tuple[float, bytes]]:
    """Two cycles: truth, a GPS fix (never read), the vehicle's step marker (the truth's time
    stamp), the clock, the estimate and command."""
    setpoint = mavlink2.MAVLink_set_position_target_local_ned_message(0, 1, 1, 1, 0, *([0.0] * 11))
    gps = mavlink2.MAVLink_gps_raw_int_message(0, 3, 0, 0, 0, 0, 0, 0, 0, 10)
    records = []
    for step in (1, 2):
        estimate = mavlink2.MAVLink_vision_position_estimate_message(
            0, 1.0 * step, 2.0, -3.0, 0, 0, 0
        )
        clock = mavlink2.MAVLink_system_time_message(0, step * 500)
        t = 0.5 * step
        marker = mavlink2.MAVLink_system_time_message(round((epoch + t) * 1e6), step * 500)
        records += [
            (t, _packet(2, _sim_state(step))),
            (t, _packet(2, gps)),
            (t, _packet(2, marker)),
            (t, _packet(255, clock)),
            (t, _packet(255, estimate)),
            (t, _packet(255, setpoint)),
        ]
    done = mavlink2.MAVLink_statustext_message(6, b"Mission complete")
    records.append((1.0, _packet(255, done)))
    return [(epoch + t, packet) for t, packet in records]


def _write(path: Path, records: list[tuple[float, bytes]], tail: bytes = b"") -> None:
    path.write_bytes(
        b"".join(struct.pack(">Q", round(t * 1e6)) + packet for t, packet in records) + tail
    )


@pytest.mark.parametrize("garbage", [b"", b"\x00" * 8 + b"not mavlink at all"])
def test_fast_reader_equals_pymavlinks_and_falls_back_on_foreign_bytes(tmp_path, garbage):
    scenario = load_scenario("along")
    tlog = tmp_path / "gcs.tlog"
    _write(tlog, _records(scenario.run.epoch_unix_s), garbage)
    fast, reference = read_tlog(tlog, scenario), read_tlog_with_mavutil(tlog, scenario)
    assert fast.ticks == reference.ticks == {0.5, 1.0}
    assert fast.completion == reference.completion == 1.0
    assert sorted(fast.estimates) == sorted(reference.estimates) == [0.5, 1.0]
    np.testing.assert_allclose(fast.estimates[1.0], [2.0, 2.0, 3.0])  # NED -> ENU
    np.testing.assert_array_equal(fast.estimates[1.0], reference.estimates[1.0])
    assert sorted(fast.truth) == sorted(reference.truth) == [(2, 0.5), (2, 1.0)]
    for key in fast.truth:
        np.testing.assert_array_equal(fast.truth[key], reference.truth[key])


def test_a_blind_cycle_is_a_cycle_without_an_estimate(tmp_path):
    """The ground station streams no estimate on a blind cycle: the work UAV's setpoint alone
    makes the cycle; the crash a vehicle reports and the station's stop are read too."""
    scenario = load_scenario("along")
    epoch = scenario.run.epoch_unix_s
    records = [r for r in _records(epoch) if r[0] != epoch + 1.0] + [
        r
        for r in _records(epoch)
        if r[0] == epoch + 1.0 and _kind(r[1]) != "VISION_POSITION_ESTIMATE"
    ]
    crash = mavlink2.MAVLink_statustext_message(0, b"Crash: structure t=0.81 at 1.0,-2.0,3.0")
    stopped = mavlink2.MAVLink_statustext_message(6, b"Run stopped: support-1 crashed")
    records += [(epoch + 1.0, _packet(2, crash)), (epoch + 1.0, _packet(255, stopped))]
    tlog = tmp_path / "gcs.tlog"
    _write(tlog, sorted(records, key=lambda r: r[0]))
    trace = read_tlog(tlog, scenario)
    assert trace.cycle_times == [0.5, 1.0] and sorted(trace.estimates) == [0.5]
    assert trace.contacts == [
        {"t": 0.81, "vehicle": "support-1", "with": "structure", "at_m": [1.0, -2.0, 3.0],
         "crash": True}
    ]  # fmt: skip
    assert trace.stopped == "support-1 crashed at 1.0 s"


def _kind(packet: bytes) -> str:
    return mavlink2.MAVLink(None).decode(bytearray(packet)).get_type()
