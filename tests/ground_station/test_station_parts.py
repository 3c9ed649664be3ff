"""The ground station's pieces in this process, against plain sockets: what it keeps of the
truth, what reaches a vehicle in one datagram, and that it never holds a multipath zone."""

from __future__ import annotations

import contextlib
import socket
import time
import types
from collections import deque
from pathlib import Path

import numpy as np
import pytest
from pymavlink import mavutil

from ground_station.control.cycle import run_cycle
from ground_station.control.run_context import build_run_context
from ground_station.estimation.localize import reports_from_messages
from ground_station.links.clock import await_step
from ground_station.links.outgoing import position_target, vision_position_estimate
from ground_station.station import GroundStation, StationConfig
from mission.config.settings import Zone
from mission.link.mavlink_udp import MavlinkCodec
from mission.link.plan_files import read_plan
from mission.world.frames import GeodeticFrame
from mission.world.model import KnownWorld, World
from mission.world.zones import MultipathZones
from vehicle_sim.mavlink import telemetry

NAMES = ("work", "support-1", "support-2", "support-3")


def _config(along, out: Path, addresses=None, **options) -> StationConfig:
    vehicles = addresses or {n: ("127.0.0.1", 9) for n in NAMES}
    return StationConfig(True, vehicles, Path(along.task.waypoints_dir), out, **options)


def _waypoints(plan) -> dict[str, np.ndarray]:
    return {"work": plan.work, **{f"support-{n + 1}": s for n, s in enumerate(plan.supports)}}


def test_sim_state_is_logged_but_never_kept_or_used(along, along_world, tmp_path):
    """Same measurements, wildly different SIM_STATE: identical commands and estimates; the
    truth is in the tlog and nowhere in the ground station's memory."""
    plan = read_plan(along)
    frame = GeodeticFrame(along.world.anchor)
    outputs = []
    for truth_shift in (0.0, 50.0):
        station = GroundStation(along_world.known(), _config(along, tmp_path / str(truth_shift)))
        context, state = build_run_context(station.world, _waypoints(plan), True, 0)
        station.clock.time_s = 0.5
        messages_rng = np.random.default_rng(11)
        for n in range(3):
            codec, y = MavlinkCodec(n + 2, 1), plan.supports[n][0]
            fix = along_world.gnss.sample_fix(y, messages_rng)
            obs = along_world.camera.observe(y, plan.work[0], messages_rng)
            usec = station.clock.time_usec
            for message in (
                telemetry.gps_raw_int(fix, frame, usec, 0.1),
                telemetry.landing_target(obs, usec, 1),
                telemetry.sim_state(y + truth_shift, np.zeros(3), frame),
            ):
                decoded = codec.decode(codec.encode(message))[0][0]
                station.links.receive(decoded, ("127.0.0.1", 9))
        reports = reports_from_messages(station.links.support_samples(), frame)
        assert all(r.fix is not None and r.relative is not None for r in reports)
        assert all("SIM_STATE" not in v.latest for v in station.links.views.values())
        output = run_cycle(state, reports, context)
        outputs.append((output.work_target, output.support_targets, state.xhat.copy()))
        station.close()
        log = mavutil.mavlink_connection(str(tmp_path / str(truth_shift) / "gcs.tlog"))
        assert log.recv_match(type="SIM_STATE") is not None  # logged for analysis
    (work_a, supports_a, xhat_a), (work_b, supports_b, xhat_b) = outputs
    np.testing.assert_array_equal(work_a, work_b)
    np.testing.assert_array_equal(xhat_a, xhat_b)
    for name in supports_a:
        np.testing.assert_array_equal(supports_a[name], supports_b[name])


def test_a_vehicles_commands_and_tick_leave_in_one_datagram_and_are_resent_together(
    along, along_world, tmp_path
):
    """Estimate, setpoint and tick reach a vehicle as one datagram, in that order, each packet
    logged at its own time; a vehicle that stays behind gets the whole batch again, encoded
    afresh (new sequence numbers, so a signed link would not refuse it as a replay)."""
    sockets = {}
    for name in NAMES:
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        sock.bind(("127.0.0.1", 0))
        sockets[name] = sock
    addresses = {n: sockets[n].getsockname() for n in NAMES}
    config = _config(along, tmp_path, addresses, step_timeout_wall_s=0.1, late_grace_wall_s=0.01)
    station = GroundStation(along_world.known(), config)
    try:
        station.clock.time_s = 2.0
        for view in station.links.views.values():
            estimate = vision_position_estimate(np.array([1.0, 2.0, 3.0]), station.clock.time_usec)
            station.links.queue_for(estimate, view)
            target = position_target(np.array([4.0, 5.0, 6.0]), 2000, view.system_id)
            station.links.queue_for(target, view)
        pending = station._start_step(station.clock.next_step())
        station.links.flush_all()
        await_step(station.links, station.clock, pending, station.timing)  # nobody answers
        resends = station.links.stats["tick_resends"]
        station.tlog.flush()
    finally:
        station.close()
    assert resends >= 4  # at least once to each vehicle
    parser = MavlinkCodec(99, 1)
    expected = ["VISION_POSITION_ESTIMATE", "SET_POSITION_TARGET_LOCAL_NED", "SYSTEM_TIME"]
    for name, sock in sockets.items():
        sock.settimeout(0.2)
        batches = []
        with contextlib.suppress(TimeoutError):
            while True:
                messages, bad = parser.decode(sock.recvfrom(65535)[0])
                assert bad == 0
                batches.append(messages)
        sock.close()
        assert len(batches) >= 2, name
        for messages in batches:
            assert [m.get_type() for m in messages] == expected, name
            assert messages[2].time_boot_ms == 2500
            np.testing.assert_allclose([messages[1].x, messages[1].y, messages[1].z], [5, 4, -6])
        seqs = [m.get_seq() for messages in batches for m in messages]
        assert len(set(seqs)) == len(seqs), "every resent packet is encoded afresh"
    # the tlog has one record a packet: commands at the cycle's time, the tick at the next
    log = mavutil.mavlink_connection(str(tmp_path / "gcs.tlog"), dialect="ardupilotmega")
    first = [log.recv_match() for _ in range(12)]
    epoch = along.run.epoch_unix_s
    assert [m.get_type() for m in first[:8]] == expected[:2] * 4
    assert all(m._timestamp == pytest.approx(epoch + 2.0) for m in first[:8])
    assert [m.get_type() for m in first[8:]] == ["SYSTEM_TIME"] * 4
    assert all(m._timestamp == pytest.approx(epoch + 2.5) for m in first[8:])


def reachable_objects(root: object):
    """Every object reachable from ``root`` through instance data (attributes, containers,
    bound methods), not through classes, modules or functions' globals."""
    opaque = (type, types.ModuleType, types.FunctionType, types.BuiltinFunctionType, str, bytes)
    opaque += (np.ndarray, int, float, bool, type(None))
    seen: set[int] = set()
    pending = deque([root])
    while pending:
        obj = pending.popleft()
        if id(obj) in seen:
            continue
        seen.add(id(obj))
        yield obj
        if isinstance(obj, opaque):
            continue
        if isinstance(obj, types.MethodType):
            pending.append(obj.__self__)
        elif isinstance(obj, dict):
            pending.extend(obj.keys())
            pending.extend(obj.values())
        elif isinstance(obj, list | tuple | set | frozenset | deque):
            pending.extend(obj)
        else:
            pending.extend(getattr(obj, "__dict__", {}).values())
            for slot in getattr(type(obj), "__slots__", ()):
                pending.append(getattr(obj, slot, None))


def _holds_a_zone(root: object) -> bool:
    return any(isinstance(o, Zone | MultipathZones | World) for o in reachable_objects(root))


def test_nothing_the_ground_station_builds_holds_a_zone(along, tmp_path):
    """Built as its command line builds it, the ground station, its context and its state
    reach no zone, no zone list and no simulated World; a vehicle's world does (the search
    finds zones where they are)."""
    assert along.world.zones  # the scenario has one
    known = KnownWorld.load("along")
    assert known.scenario.world.zones == []
    assert not hasattr(known, "zone_offset") and not hasattr(known, "zones")
    station = GroundStation(known, _config(along, tmp_path))
    try:
        context, state = build_run_context(known, _waypoints(read_plan(along)), True, 0)
        station.context = context
        for built in (station, context, state):
            assert not _holds_a_zone(built)
    finally:
        station.close()
    assert _holds_a_zone(World(along))


def test_the_ground_station_refuses_a_world_with_zones(along, along_world, tmp_path):
    with pytest.raises(TypeError, match="KnownWorld"):
        GroundStation(along_world, _config(along, tmp_path))
    with pytest.raises(TypeError, match="KnownWorld"):
        build_run_context(along_world, _waypoints(read_plan(along)), True, 0)


@pytest.mark.parametrize("escape_starts", [True, False])
def test_escape_starts_are_asked_for_where_g_has_risen_unless_switched_off(escape_starts):
    from ground_station.control.plan import support_request
    from ground_station.control.work_mpc import WorkPrediction
    from mission.config.scenario import load_scenario

    scenario = load_scenario("along", {"control.escape_starts": escape_starts})
    known = KnownWorld(scenario)
    context, state = build_run_context(known, _waypoints(read_plan(scenario)), True, 0)
    horizon = scenario.control.horizon_steps
    work = WorkPrediction(np.repeat(state.xhat[None], horizon + 1, 0), np.zeros(horizon + 1, int))
    assert not support_request(state, "support-1", work, context).escape  # G as predicted
    context.g.values += 2.0  # GNSS worse everywhere than the prior map said
    assert support_request(state, "support-1", work, context).escape is escape_starts


def test_a_vehicle_is_lost_after_simulated_seconds_and_never_a_wall_moment(along, tmp_path):
    assert _config(along, tmp_path).silence_limit_s == 3.0  # lockstep: 3 s of simulated time
    assert _config(along, tmp_path, speedup=0.5).silence_limit_s == 3.0  # 6 s of wall time
    assert _config(along, tmp_path, speedup=10.0).silence_limit_s == 20.0  # 2 s, not 0.3 s


def test_a_ground_station_without_vehicles_says_what_it_waits_for_and_for_how_long(
    along, tmp_path, capsys
):
    """Nothing listens at the vehicles' addresses: it says at once how long it will wait and
    for which vehicles where, and after that names each one it never heard."""
    from ground_station.links.vehicle_links import StationError
    from ground_station.preflight import connect

    silent = {n: ("127.0.0.1", 9) for n in NAMES}  # the discard port: nobody answers
    station = GroundStation(KnownWorld.load("along"), _config(along, tmp_path, silent))
    try:
        started = time.monotonic()
        with pytest.raises(StationError, match="no heartbeat from work, support-1, support-2"):
            connect(station.links, 1.0)
        assert time.monotonic() - started < 5.0
    finally:
        station.close()
    said = capsys.readouterr().err
    assert "ground station waiting up to 1 s for work 127.0.0.1:9, support-1 127.0.0.1:9" in said
