"""Truth on the ground station's clock: offsets from TIMESYNC, interpolation, and the metrics
of a hand-made real-time tlog (vehicles on clocks of their own, stepping out of phase with
the ground station's cycles) against the answers worked out by hand."""

from __future__ import annotations

import os
import struct
from pathlib import Path

import numpy as np
import pytest

os.environ.setdefault("MAVLINK20", "1")
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.analysis.metrics import read_tlog, trace_metrics
from mission.analysis.truth import TimesyncReply, clock_offsets, interpolate
from mission.world.frames import GeodeticFrame
from tests.tlog_reference import read_tlog_with_mavutil
from vehicle_sim.mavlink import telemetry

OFFSETS = {1: 3.2, 2: 11.7}  # each vehicle's clock minus the ground station's (s)
PHASES = {1: 0.13, 2: 0.31}  # when in each 0.5 s the vehicle steps, on the station's clock
LATENCY_S = 0.001


def test_clock_offsets_take_the_shortest_round_trip():
    replies = [
        TimesyncReply(
            2, tc1_ns=round(11.7e9 + 1.02e9), ts1_ns=1_000_000_000, received_ns=1_040_000_000
        ),
        TimesyncReply(
            2, tc1_ns=round(11.7e9 + 2.001e9), ts1_ns=2_000_000_000, received_ns=2_002_000_000
        ),
        TimesyncReply(3, tc1_ns=0, ts1_ns=5, received_ns=6),  # a request: no offset
    ]
    assert clock_offsets(replies) == {2: pytest.approx(11.7, abs=1e-9)}


def test_interpolation_is_exact_on_samples_linear_between_and_unknown_across_gaps():
    times = np.array([0.0, 0.5, 1.0, 3.0])
    positions = np.array([[0.0, 0, 0], [1.0, 0, 0], [2.0, 2, 0], [9.0, 9, 9]])
    at = np.array([0.5, 0.75, 2.0, -0.1, 3.0, 3.1])
    found, known = interpolate(times, positions, at, max_gap_s=1.0)
    assert known.tolist() == [True, True, False, False, True, False]
    assert found[0].tolist() == [1.0, 0, 0] and found[4].tolist() == [9.0, 9, 9]
    np.testing.assert_allclose(found[1], [1.5, 1.0, 0.0])


def _work(t: float) -> np.ndarray:
    return np.array([-12.0 + 0.2 * t, -3.0, 7.0])


def _support(t: float) -> np.ndarray:
    """Crosses Along's zone (x in [-7.5, -1.5] at y 6.5, z 8.5) at 0.5 m/s."""
    return np.array([-10.1 + 0.5 * t, 6.5, 8.5])


def _packet(system: int, message) -> bytes:
    return bytes(message.pack(mavlink2.MAVLink(None, srcSystem=system, srcComponent=1)))


def _realtime_tlog(along, path: Path) -> list[float]:
    """20 s of a real-time run; returns the cycle times."""
    frame = GeodeticFrame(along.world.anchor)
    epoch = along.run.epoch_unix_s
    records: list[tuple[float, bytes]] = []
    for system, offset in OFFSETS.items():  # one TIMESYNC exchange each, 2 ms round trip
        sent = 0.2
        records.append(
            (sent, _packet(255, mavlink2.MAVLink_timesync_message(0, round(sent * 1e9))))
        )
        reply = mavlink2.MAVLink_timesync_message(
            round((sent + LATENCY_S + offset) * 1e9), round(sent * 1e9)
        )
        records.append((sent + 2 * LATENCY_S, _packet(system, reply)))
    truth = {1: _work, 2: _support}
    for step in range(40):
        for system, phase in PHASES.items():
            t = phase + 0.5 * step  # the station's clock
            vehicle_usec = round((epoch + t + OFFSETS[system]) * 1e6)
            state = telemetry.sim_state(truth[system](t), np.zeros(3), frame)
            marker = mavlink2.MAVLink_system_time_message(vehicle_usec, 0)
            records.append((t + LATENCY_S, _packet(system, state)))
            records.append((t + LATENCY_S, _packet(system, marker)))
    setpoint = mavlink2.MAVLink_set_position_target_local_ned_message(0, 1, 1, 1, 0, *([0.0] * 11))
    cycles = [0.5 * k for k in range(1, 40)]
    for t in cycles:
        x = _work(t) + [0.0, 0.1, 0.0]  # the estimate: 0.1 m off, at the cycle's time
        north, east, down = x[1], x[0], -x[2]
        estimate = mavlink2.MAVLink_vision_position_estimate_message(0, north, east, down, 0, 0, 0)
        records += [(t, _packet(255, estimate)), (t, _packet(255, setpoint))]
    records.sort(key=lambda record: record[0])
    path.write_bytes(b"".join(struct.pack(">Q", round((epoch + t) * 1e6)) + p for t, p in records))
    return cycles


def test_a_realtime_tlogs_metrics_pair_truth_and_estimates_at_the_cycles_times(
    along, along_world, tmp_path
):
    tlog = tmp_path / "gcs.tlog"
    cycles = _realtime_tlog(along, tlog)
    trace = read_tlog(tlog, along)
    reference = read_tlog_with_mavutil(tlog, along)
    assert trace.truth.keys() == reference.truth.keys()
    assert trace.mode == "realtime"
    # each truth sample at its own stamp: the station's time of the step, not of its arrival
    np.testing.assert_allclose(
        trace.track(2)[0], [PHASES[2] + 0.5 * k for k in range(40)], atol=2e-4
    )
    metrics = trace_metrics(trace, along_world)
    # by hand: every cycle lies within the truth's span; the estimate is 0.1 m off throughout
    # (truth from SIM_STATE is kept to 1e-7 degrees, about 1 cm)
    assert metrics["control_cycles"] == len(cycles)
    assert metrics["work_error_m"]["mean"] == pytest.approx(0.1, abs=0.012)
    inside = [t for t in cycles if along_world.in_zone(_support(t)[None])[0]]
    assert len(inside) > 5
    assert metrics["multipath_steps"] == {"support-1": len(inside)}
