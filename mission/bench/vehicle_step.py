"""A vehicle's lockstep step, warm: the whole per-step path of a support in this process.

What a vehicle process does each step of a run, without the process: decode the station's
setpoint and estimate from their packets and take them (the fence's checks), step with the
other vehicles' moves (contact with them, the structure and the ground), publish the step's
telemetry (the GNSS fix, the camera's measurement, the states) and encode it. The support flies
its Along waypoints among the others flying theirs, one step after another, so the caches stay
warm. ``vehicle_cpu_per_step_us`` of ``--only run`` is a vehicle process's whole step in a run:
this work, what only a process does (its loop, sockets, the truth channel), and six other
processes running between two of its steps (docs/benchmarks.md, "A vehicle's step in a run").
"""

from __future__ import annotations

import statistics
import time

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.bench.result import BenchResult

POSITION_ONLY = 0b0000_1101_1111_1000  # the station's setpoints (position, no yaw)
# The others' moves are judged for contact as in a run, but 40 m up: the plan's straight legs
# between waypoints cross where the supports' MPCs would keep them apart.
AWAY_M = np.array([0.0, 0.0, 40.0])
STEP_M = 0.4  # how far the vehicles move a step along their waypoints (within a step's reach)


def bench_vehicle_step(repeats: int = 5) -> list[BenchResult]:
    """CPU microseconds of a support's warm step: the median of ``repeats`` flights of its
    Along path (~180 steps each, a fresh vehicle each)."""
    timings = [_warm_step_us() for _ in range(repeats)]
    value = statistics.median(timings)
    return [BenchResult("vehicle_step_warm_us", value, "us", "reference", None)]


def vehicle_cpu_per_step_us(summary: dict) -> float:
    """A run's supports' CPU microseconds a step, their mean (``summary.json``: each
    process's CPU seconds; a vehicle steps once a control cycle); NaN where the run does not
    say them."""
    supports = [s for name, s in summary.get("cpu_s", {}).items() if name.startswith("support-")]
    if not supports or not summary.get("control_cycles"):
        return float("nan")
    return statistics.mean(supports) / summary["control_cycles"] * 1e6


def _warm_step_us() -> float:
    from mission.link.mavlink_udp import MavlinkCodec
    from mission.link.plan_files import read_plan
    from mission.link.vehicle_identity import VehicleIdentity
    from mission.world.frames import enu_to_ned
    from mission.world.model import World
    from vehicle_sim.dynamics.contact import as_sent
    from vehicle_sim.vehicle import Vehicle

    world = World.load("along")
    plan = read_plan(world.scenario)
    waypoints = {"work": plan.work, **{f"support-{n + 1}": p for n, p in enumerate(plan.supports)}}
    paths = _flown_together(waypoints, STEP_M)  # every path as many steps long
    own = paths["support-1"]
    sent: list = []
    vehicle = Vehicle(
        VehicleIdentity.parse("support-1"), world.scenario, world, own[0], 0, sent.append
    )
    vehicle.arm(True)
    vehicle.change_mode(mavlink2.COPTER_MODE_GUIDED)
    station, own_codec = MavlinkCodec(255, 190), MavlinkCodec(2, 1)
    system_id = vehicle.identity.system_id

    def packets(i: int) -> list[bytes]:
        target, belief = enu_to_ned(own[i + 1]), enu_to_ned(own[i])  # as the station believes
        stamp = 500 * (i + 1)
        setpoint = mavlink2.MAVLink_set_position_target_local_ned_message(
            stamp, system_id, 1, mavlink2.MAV_FRAME_LOCAL_NED, POSITION_ONLY, *target, *[0] * 8
        )
        estimate = mavlink2.MAVLink_vision_position_estimate_message(stamp, *belief, 0, 0, 0)
        return [station.encode(setpoint), station.encode(estimate)]

    def moves(i: int) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        return {
            name: (as_sent(path[i] + AWAY_M), as_sent(path[i + 1] + AWAY_M))
            for name, path in paths.items()
            if name != "support-1"
        }

    steps = len(own) - 1
    inputs = [(packets(i), moves(i), paths["work"][i + 1]) for i in range(steps)]
    sent.clear()
    start = time.process_time()
    for incoming, others, work in inputs:
        for packet in incoming:
            for message in own_codec.decode(packet)[0]:
                vehicle.handle(message, 0.0)
        vehicle.step(others)
        vehicle.publish(work)
        for message in sent:
            own_codec.encode(message)
        sent.clear()
    elapsed = time.process_time() - start
    if vehicle.crashed or vehicle.counters.rejected:  # it must do a flying vehicle's work
        raise RuntimeError(f"the support did not fly its path: {vehicle.counters.rejected}")
    return elapsed / steps * 1e6


def _flown_together(waypoints: dict[str, np.ndarray], step_m: float) -> dict[str, np.ndarray]:
    """Every vehicle's waypoints joined by a position per step, all reaching their k-th
    waypoint at the same step (as the plan's formation does), no step longer than ``step_m``."""
    legs = np.array([np.linalg.norm(np.diff(p, axis=0), axis=1) for p in waypoints.values()])
    counts = np.maximum(np.ceil(legs.max(axis=0) / step_m).astype(int), 1)
    flown = {}
    for name, points in waypoints.items():
        parts = [
            a + (b - a) * (np.arange(n)[:, None] / n)
            for a, b, n in zip(points[:-1], points[1:], counts, strict=True)
        ]
        flown[name] = np.vstack([*parts, points[-1:]])
    return flown
