"""Real time: each vehicle's clock offset from TIMESYNC, the age of a measurement at a cycle,
and measurements brought to the cycle's time; in lockstep all of it is inert."""

from __future__ import annotations

import types
from pathlib import Path

import numpy as np
import pytest

from ground_station.estimation.align import align
from ground_station.estimation.localize import SupportReport
from ground_station.links.clock import StationClock
from ground_station.links.clock_sync import ClockOffsets
from ground_station.links.tlog import TlogWriter
from ground_station.links.vehicle_links import MAX_AGE_STEPS, VehicleLinks
from ground_station.state.station_state import StationState
from mission.link.impairment import LinkSettings


def test_the_offset_is_ntps_estimate_of_the_exchange_with_the_shortest_round_trip():
    offsets = ClockOffsets()
    assert offsets.offset_s(2) is None
    # vehicle clock = ground station's + 7.25 s; replies after 40 ms and 4 ms round trips,
    # the slow one answered late in its trip (an asymmetric delay NTP cannot see)
    offsets.observe(
        2, tc1=round((10.0 + 0.035 + 7.25) * 1e9), ts1=10_000_000_000, received_ns=10_040_000_000
    )
    offsets.observe(
        2, tc1=round((20.0 + 0.002 + 7.25) * 1e9), ts1=20_000_000_000, received_ns=20_004_000_000
    )
    assert offsets.offset_s(2) == pytest.approx(7.25, abs=1e-9)
    offsets.observe(2, tc1=0, ts1=1, received_ns=2)  # a request, not an answer: ignored
    offsets.observe(2, tc1=5, ts1=9, received_ns=2)  # arrived before it left: ignored
    assert offsets.offset_s(2) == pytest.approx(7.25, abs=1e-9)
    assert offsets.offset_s(3) is None


def _links(along, tmp_path: Path, speedup: float | None) -> VehicleLinks:
    clock = StationClock(along.run, along.control.t_cont_s, speedup)
    vehicles = {"work": ("127.0.0.1", 9), "support-1": ("127.0.0.1", 9)}
    return VehicleLinks(vehicles, clock, TlogWriter(tmp_path / "t.tlog"), None, LinkSettings(), 0)


def _stamped(clock: StationClock, vehicle_time_s: float):
    usec = round((clock.run.epoch_unix_s + vehicle_time_s) * 1e6)
    return types.SimpleNamespace(time_usec=usec)


def test_a_measurements_age_is_the_cycle_time_minus_its_stamp_on_the_stations_clock(
    along, tmp_path
):
    links = _links(along, tmp_path, speedup=10.0)
    clock = links.clock
    clock.time_s = 100.0
    message = _stamped(clock, 100.0 + 7.25 - 0.3)  # taken 0.3 s before the cycle
    assert links.age_s("support-1", message) is None  # its clock not known yet
    links.offsets.observe(2, round(57.25e9), round(50e9), round(50e9))
    assert links.age_s("support-1", message) == pytest.approx(0.3, abs=1e-6)
    too_old = _stamped(clock, 100.0 + 7.25 - MAX_AGE_STEPS * clock.step_s - 0.01)
    assert links.age_s("support-1", too_old) is None
    assert links.age_s("support-1", None) is None
    links.close()


def test_in_lockstep_every_age_is_zero(along, tmp_path):
    links = _links(along, tmp_path, speedup=None)
    links.clock.time_s = 3.0
    assert links.age_s("support-1", _stamped(links.clock, 3.0)) == 0.0
    links.close()


def _state() -> StationState:
    state = StationState(np.zeros(3), {"support-1": np.zeros(3)}, 0)
    state.last_work_command = np.array([0.10, 0.0, 0.0])  # per 0.5 s cycle: 0.2 m/s east
    state.last_support_command["support-1"] = np.array([0.0, 0.05, 0.0])  # 0.1 m/s north
    return state


def test_measurements_are_propagated_by_the_commanded_motion_since_they_were_taken():
    fix, relative = np.array([1.0, 2.0, 3.0]), np.array([4.0, -1.0, 0.5])
    report = SupportReport("support-1", fix, relative, None, 0.2, 0.3)
    (aligned,) = align([report], _state(), 0.5)
    np.testing.assert_allclose(aligned.fix, fix + [0.0, 0.1 * 0.2, 0.0])
    np.testing.assert_allclose(aligned.relative, relative + [0.2 * 0.3, -0.1 * 0.3, 0.0])
    # taken together, mu = p + r moves with the work UAV alone
    same_time = SupportReport("support-1", fix, relative, None, 0.3, 0.3)
    (moved,) = align([same_time], _state(), 0.5)
    np.testing.assert_allclose(moved.fix + moved.relative, fix + relative + [0.2 * 0.3, 0, 0])


def test_a_measurement_of_age_zero_is_used_as_it_is():
    report = SupportReport("support-1", np.array([1.0, 2.0, 3.0]), None, None, 0.0, 0.0)
    (aligned,) = align([report], _state(), 0.5)
    assert aligned is report


def test_the_real_time_schedule_keeps_its_beat_and_skips_cycles_it_fell_behind():
    """Cycle n runs at n t_cont after the flight starts; a cycle that overran is not made up:
    the next one is the latest due."""
    import time

    from ground_station.links.clock import CYCLE_LAG_STEPS, PendingStep, await_step

    class Links:  # receives nothing for as long as the schedule asks, and notes how long
        def __init__(self) -> None:
            self.waits: list[float] = []

        def pump(self, seconds, until=None):
            self.waits.append(seconds)
            time.sleep(seconds)

    run = types.SimpleNamespace(epoch_unix_s=0.0, timeout_s=100.0)
    clock = StationClock(run, 0.5, speedup=10.0)  # a step is 50 ms of wall time
    clock.begin_flight()
    links = Links()
    await_step(links, clock, PendingStep(0.5), None)
    assert clock.time_s == 0.5
    time.sleep(0.16)  # more than three steps of wall time pass in the cycle (at 0.5 s)
    await_step(links, clock, PendingStep(0.5), None)
    assert clock.time_s in (2.0, 2.5)  # the latest due cycle (or the next), not 1.0
    # the first cycle waits for the beat (at most a step away) and a step; one behind, not at all
    assert links.waits[0] <= 0.1 + 1e-9 and links.waits[1] == 0.0
    assert 0 < CYCLE_LAG_STEPS < 1


def test_the_beat_is_a_whole_number_of_steps_of_unix_time_plus_the_lag():
    import time

    from mission.procs.wall_grid import next_grid_instant

    before = time.time()
    monotonic, unix = next_grid_instant(0.05, lag_s=0.01)
    assert before - 1e-6 <= unix <= before + 0.05 + 1e-6
    assert round((unix - 0.01) / 0.05, 6) % 1 == 0
    assert abs((monotonic - time.monotonic()) - (unix - time.time())) < 0.005
