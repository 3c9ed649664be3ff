"""Contact detection on in-process vehicles: two driven into each other, one into the deck, one
into the ground, each detected at the right step and reported; a near miss is not."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.config.scenario import load_scenario
from mission.link.vehicle_identity import VehicleIdentity
from mission.world.model import World
from vehicle_sim.dynamics.contact import as_sent
from vehicle_sim.vehicle import Vehicle

RADIUS = 0.25  # the default vehicle.radius_m


@pytest.fixture(scope="module")
def worlds(along_world):
    flying_on = World(load_scenario("along", {"run.stop_on_crash": False}))
    return {True: along_world, False: flying_on}


def _vehicle(world: World, name: str, home, target) -> tuple[Vehicle, list]:
    sent: list = []
    vehicle = Vehicle(
        VehicleIdentity.parse(name), world.scenario, world, np.array(home), 0, sent.append
    )
    vehicle.arm(True)
    vehicle.kinematics.target = np.array(target, dtype=float)
    sent.clear()
    return vehicle, sent


def _texts(sent: list) -> list[tuple[int, str]]:
    return [(m.severity, m.text) for m in sent if m.get_type() == "STATUSTEXT"]


def _fly_pair(a: Vehicle, b: Vehicle, steps: int) -> list[int]:
    """Step both, each told the other's last move as the truth channel carries it; the step
    calls (1-based) at which each first reported a contact."""
    reported = {id(a): 0, id(b): 0}
    for call in range(1, steps + 1):
        others = {a: {b.identity.name: b._last_move}, b: {a.identity.name: a._last_move}}
        for vehicle in (a, b):
            vehicle.step(others[vehicle] if call > 1 else None)
            if vehicle.watch.contacts and not reported[id(vehicle)]:
                reported[id(vehicle)] = call
    return [reported[id(a)], reported[id(b)]]


def test_two_vehicles_flown_head_on_both_crash_at_the_step_they_meet(worlds):
    a, sent_a = _vehicle(worlds[True], "support-1", [0.0, -12.0, 5.0], [10.0, -12.0, 5.0])
    b, sent_b = _vehicle(worlds[True], "support-2", [4.0, -12.0, 5.0], [-10.0, -12.0, 5.0])
    # 0.5 m a step each: 4 m apart, the gap crosses 2 r during the fourth step (t 1.5-2.0 s),
    # judged at the start of the fifth, before either moves again
    assert _fly_pair(a, b, 8) == [5, 5]
    assert a.crashed and b.crashed
    np.testing.assert_allclose(a.kinematics.truth, [2.0, -12.0, 5.0], atol=1e-5)
    np.testing.assert_allclose(b.kinematics.truth, [2.0, -12.0, 5.0], atol=1e-5)
    (severity, text), *_ = _texts(sent_a)
    assert severity == mavlink2.MAV_SEVERITY_EMERGENCY
    assert text == "Crash: support-2 t=2.00 at 2.0,-12.0,5.0"
    assert _texts(sent_b)[0][1] == "Crash: support-1 t=2.00 at 2.0,-12.0,5.0"
    assert a.heartbeat().system_status == mavlink2.MAV_STATE_EMERGENCY
    assert not a.armed


def test_a_near_miss_just_outside_two_radii_is_no_contact_and_just_inside_is(worlds):
    for offset, touching in ((2 * RADIUS + 0.01, False), (2 * RADIUS - 0.01, True)):
        a, _ = _vehicle(worlds[True], "support-1", [0.0, -12.0, 5.0], [10.0, -12.0, 5.0])
        b, _ = _vehicle(
            worlds[True], "support-2", [4.0, -12.0 + offset, 5.0], [-10.0, -12.0 + offset, 5.0]
        )
        _fly_pair(a, b, 10)
        assert a.crashed is touching and b.crashed is touching


def test_a_vehicle_flown_up_into_the_deck_stops_where_it_touched(worlds, along_world):
    vehicle, sent = _vehicle(worlds[True], "support-1", [0.0, 0.0, 6.0], [0.0, 0.0, 12.0])
    positions = []
    for _ in range(8):
        vehicle.step()
        positions.append(vehicle.kinematics.truth.copy())
    # z 6.0 -> 7.5 in three steps; the fourth (7.5 -> 8.0) is sampled every r / 4 and first
    # comes within r of the underside (z = 8) at 7.8125
    np.testing.assert_allclose(positions[3], [0.0, 0.0, 7.8125])
    assert all(np.array_equal(p, positions[3]) for p in positions[3:])
    assert _texts(sent) == [
        (mavlink2.MAV_SEVERITY_EMERGENCY, "Crash: structure t=1.81 at 0.0,0.0,7.8")
    ]
    # an independent distance: trimesh's, to the structure's mesh
    query = trimesh.proximity.ProximityQuery(along_world.structure.mesh)
    before, at = np.abs(query.signed_distance([positions[2], positions[3]]))
    assert before >= RADIUS > at


def test_a_vehicle_flown_into_the_ground_crashes_and_a_crashed_vehicle_stays_down(worlds):
    vehicle, sent = _vehicle(worlds[True], "support-1", [0.0, -12.0, 1.0], [0.0, -12.0, -5.0])
    # 1.0 -> 0.5, then 0.5 -> 0.0 sampled every r / 4: 0.1875 is the first within r
    for _ in range(4):
        vehicle.step()
    np.testing.assert_allclose(vehicle.kinematics.truth, [0.0, -12.0, 0.1875])
    assert _texts(sent)[0][1] == "Crash: ground t=0.81 at 0.0,-12.0,0.2"
    setpoint = mavlink2.MAVLink_set_position_target_local_ned_message(
        0, 2, 1, mavlink2.MAV_FRAME_LOCAL_NED, 0b0000_1101_1111_1000, 0, 0, -5, *[0] * 8
    )
    vehicle.handle(setpoint, 0.0)
    assert vehicle.counters.rejected == {"setpoint: crashed": 1}
    arm = mavlink2.MAVLink_command_long_message(2, 1, 400, 0, 1, 0, 0, 0, 0, 0, 0)
    arm._header.srcSystem, arm._header.srcComponent = 255, 190
    vehicle.handle(arm, 0.0)
    assert not vehicle.armed


def test_without_stop_on_crash_a_contact_is_reported_once_and_the_vehicle_flies_on(worlds):
    vehicle, sent = _vehicle(worlds[False], "support-1", [0.0, -12.0, 1.0], [0.0, -12.0, 0.1])
    for _ in range(6):
        vehicle.step()
    assert not vehicle.crashed and vehicle.armed
    np.testing.assert_allclose(vehicle.kinematics.truth, [0.0, -12.0, 0.1])
    assert _texts(sent) == [
        (mavlink2.MAV_SEVERITY_CRITICAL, "Contact: ground t=0.86 at 0.0,-12.0,0.2")
    ]
    assert len(vehicle.watch.contacts) == 1


def test_two_vehicles_judge_their_approach_from_the_same_numbers():
    """Each side rounds its own position as the channel rounds the other's: the verdicts agree
    bit for bit."""
    from mission.world.proximity import closest_approach

    rng = np.random.default_rng(3)
    for _ in range(200):
        a0, a1, b0, b1 = (as_sent(p) for p in rng.uniform(-20, 20, (4, 3)))
        assert closest_approach(a0, a1, b0, b1) == closest_approach(b0, b1, a0, a1)
