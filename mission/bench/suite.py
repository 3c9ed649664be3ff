"""``python -m mission bench``: every benchmark of the project, as a table or one JSON object.

Benchmarks measure medians over repeats on this machine; targets are the issues' figures.
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import TextIO

from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.bench.floor import bench_floor
from mission.bench.integrity import bench_integrity
from mission.bench.margins import bench_margins
from mission.bench.multipath import bench_multipath
from mission.bench.result import BenchResult
from mission.bench.roles import bench_roles
from mission.bench.run_command import batch_wall_s, run_as_command
from mission.bench.solver_ratios import interpreted_over_compiled, scipy_over_casadi
from mission.bench.study import bench_studies
from mission.bench.vehicle_step import bench_vehicle_step, vehicle_cpu_per_step_us
from mission.bench.view import bench_view
from mission.link.mavlink_udp import MavlinkCodec, MessageQueue, UdpEndpoint
from mission.procs.machine_speed import REFERENCE_LOOP_S, children_cpu_s, python_loop_s
from mission.procs.stopping import stop_processes

REALTIME_FACTOR_TARGET = 100.0  # Along AC's lockstep real-time factor there
MULTICOPTER_ALONG = (  # Along AC flown by quadrotors in a 3 m/s gusty wind
    "extends: along\nname: along-multicopter\nvehicle: {dynamics: multicopter}\n"
    "world: {wind: {speed_m_s: 3.0}}\n"
)
TABLE3_WALL_TARGET_S = 150.0  # the Table 3 batch on two cores there
RUN_OVER_DETACHED_TARGET = 1.6  # a run's CPU over its decisions' alone (the floor's)


def bench_sigma0_map(repeats: int = 5) -> list[BenchResult]:
    """Time to build the sigma_0 map of the default workspace (40,000 voxels x 15 satellites)."""
    from mission.world.model import World

    world = World.load("along")
    times = [world.sigma0_map().build_s for _ in range(repeats)]
    median = statistics.median(times)
    return [BenchResult("sigma0_map_build_s", median, "s", "<= 3", median <= 3.0)]


def bench_vehicle(steps: int = 1000, repeats: int = 3, pings: int = 500) -> list[BenchResult]:
    """Lockstep steps per second of one vehicle under a minimal driver; COMMAND_LONG round trip."""
    process, address = _start_vehicle()
    try:
        endpoint = UdpEndpoint(MavlinkCodec(255, 190))
        queue = MessageQueue(endpoint)
        steps_per_s = statistics.median(
            _drive_lockstep(endpoint, address, steps, first=1 + r * steps) for r in range(repeats)
        )
        rtts = []
        command = mavlink2.MAV_CMD_SET_MESSAGE_INTERVAL
        for _ in range(pings):
            sent = time.perf_counter()
            endpoint.send(
                mavlink2.MAVLink_command_long_message(
                    2, 1, command, 0, mavlink2.MAVLINK_MSG_ID_HEARTBEAT, 0, 0, 0, 0, 0, 0
                ),
                [address],
            )
            _wait(queue, lambda m: m.get_type() == "COMMAND_ACK" and m.command == command)
            rtts.append((time.perf_counter() - sent) * 1000)
        endpoint.close()
    finally:
        stop_processes([process], grace_s=10.0)
    rtt = statistics.median(rtts)
    return [
        BenchResult("vehicle_steps_per_s", steps_per_s, "steps/s", ">= 2000", steps_per_s >= 2000),
        BenchResult("mavlink_rtt_ms_median", rtt, "ms", "< 1", rtt < 1.0),
    ]


def _drive_lockstep(
    endpoint: UdpEndpoint, address: tuple[str, int], steps: int, first: int = 1
) -> float:
    """Tick the vehicle ``steps`` times as a minimal driver would: raw datagrams, no decoding
    except spotting the SYSTEM_TIME step marker by its message id in the packet headers."""
    codec = endpoint.codec
    ticks = [
        codec.encode(mavlink2.MAVLink_system_time_message(0, 500 * k))
        for k in range(first, first + steps)
    ]
    marker = mavlink2.MAVLINK_MSG_ID_SYSTEM_TIME.to_bytes(3, "little")
    sock = endpoint.sock
    sock.setblocking(True)
    sock.settimeout(5.0)
    start = time.perf_counter()
    deadline = start + 60.0
    for tick in ticks:
        sock.sendto(tick, address)
        while True:
            datagram = sock.recv(65535)
            if _has_message(datagram, marker):
                break
            if time.perf_counter() > deadline:
                raise RuntimeError("the vehicle stopped answering clock ticks")
    elapsed = time.perf_counter() - start
    sock.setblocking(False)
    return steps / elapsed


def _has_message(datagram: bytes, message_id: bytes) -> bool:
    """Whether a datagram of MAVLink 2 packets holds one with this id (headers only)."""
    offset = 0
    while offset + 10 <= len(datagram) and datagram[offset] == 0xFD:
        if datagram[offset + 7 : offset + 10] == message_id:
            return True
        signed = datagram[offset + 2] & 0x01
        offset += 12 + datagram[offset + 1] + (13 if signed else 0)
    return False


def _start_vehicle() -> tuple[subprocess.Popen, tuple[str, int]]:
    process = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "vehicle_sim",
            "--vehicle",
            "support-1",
            "--port",
            "0",
            "--home",
            "0",
            "-10",
            "7",
            "--exit-with-parent",
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert process.stderr is not None
    line = process.stderr.readline()
    if "listening on" not in line:
        process.kill()
        raise RuntimeError(f"vehicle did not start: {line.strip()}")
    host_port = line.split("listening on ")[1].split(",")[0]
    host, port = host_port.rsplit(":", 1)
    return process, (host, int(port))


def _wait(queue: MessageQueue, match: Callable, timeout_s: float = 5.0) -> None:
    deadline = time.perf_counter() + timeout_s
    while (got := queue.next(deadline - time.perf_counter())) is not None:
        if match(got[0]):
            return
    raise RuntimeError("benchmark peer stopped answering")


def bench_ground_station(
    cycles: int = 160, scipy_problems: int = 5, repeats: int = 3
) -> list[BenchResult]:
    """MPC solve times and cycle time over a detached Along run (AC), each the median over
    ``repeats`` runs; scipy vs casadi."""
    import numpy as np

    from mission.bench.detached import run_detached
    from mission.link.plan_files import read_plan
    from mission.world.model import World

    world = World.load("along")
    plan = read_plan(world.scenario)
    waypoints = {
        "work": plan.work,
        **{f"support-{n + 1}": plan.supports[n] for n in range(len(plan.supports))},
    }
    medians, p95s, cycles_ms = [], [], []
    for _ in range(repeats):  # the same run each time: only the timings differ
        run = run_detached(world, waypoints, adaptive=True, seed=0, max_cycles=cycles)
        solves = [p.solve_ms for o in run.outputs for p in o.support_plans.values()]
        medians.append(statistics.median(solves))
        p95s.append(float(np.percentile(solves, 95)))
        cycles_ms.append(statistics.median(o.cycle_ms for o in run.outputs))
    ratio = scipy_over_casadi(world, plan, scipy_problems)
    interpreted = interpreted_over_compiled(world, plan)
    median, p95 = statistics.median(medians), statistics.median(p95s)
    cycle = statistics.median(cycles_ms)
    return [
        BenchResult("support_mpc_solve_ms_median", median, "ms", "<= 5", median <= 5),
        BenchResult("support_mpc_solve_ms_p95", p95, "ms", "<= 15", p95 <= 15),
        BenchResult("gcs_cycle_ms_median", cycle, "ms", "<= 25", cycle <= 25),
        BenchResult("scipy_over_casadi_ratio", ratio, "x", ">= 10", ratio >= 10),
        BenchResult("interpreted_over_compiled_ratio", interpreted, "x", "reference", None),
    ]


def bench_runs(trials: int = 15, jobs: int = 2, repeats: int = 3) -> list[BenchResult]:
    """Lockstep runs, each a ``python -m mission run`` process as a user or a batch starts it:
    Along AC's real-time factor and CPU seconds (all its processes'), the medians of
    ``repeats`` runs (MPC helper where there is a core for it); the real-time factor of the
    same runs flown by multicopters in a 3 m/s wind (alternating with those), against 0.8 of
    the kinematic one; and the wall time of the full
    Table 3 batch, estimated as trials x the wall time of one run per scenario and method made
    as the batch makes them (``jobs`` at a time, whole commands)."""
    import tempfile

    from mission.studies.local_engine import helper_has_a_core

    factors, cpus, flying, vehicle_us = [], [], [], []
    in_batch = helper_has_a_core(jobs, os.cpu_count() or 1)
    with tempfile.TemporaryDirectory(prefix="bench-run-") as temp:
        multicopter = Path(temp) / "along-multicopter.yaml"
        multicopter.write_text(MULTICOPTER_ALONG)
        for repeat in range(repeats):  # alternately, so the machine's drift touches both
            out = Path(temp) / f"along-ac-{repeat}"
            before = children_cpu_s()
            summary = run_as_command("along", "ac", out)
            cpus.append(children_cpu_s() - before)
            factors.append(summary["realtime_factor"])
            vehicle_us.append(vehicle_cpu_per_step_us(summary))
            out = Path(temp) / f"along-multicopter-{repeat}"
            flying.append(run_as_command(str(multicopter), "ac", out)["realtime_factor"])
        batch = [(name, method) for name in ("along", "wall") for method in ("ac", "nac")]
        batch_s = batch_wall_s(batch, Path(temp), jobs, in_batch)
    factor = statistics.median(factors)
    flying_ratio = statistics.median(flying) / factor
    estimate = trials * batch_s  # the batch is that round of runs, trials times
    cpu = statistics.median(cpus)
    said = [us for us in vehicle_us if us == us]  # NaN where a run did not say its vehicles'
    per_step = statistics.median(said) if said else float("nan")
    slowness = python_loop_s() / REFERENCE_LOOP_S  # this machine's speed, after the runs
    factor_target = REALTIME_FACTOR_TARGET / slowness
    t3_target = TABLE3_WALL_TARGET_S * slowness
    flown = statistics.median(flying)
    return [
        BenchResult(
            "realtime_factor_lockstep",
            factor,
            "x",
            f">= {factor_target:.0f}",
            factor >= factor_target,
        ),
        BenchResult(
            "realtime_factor_multicopter", flown, "x", f">= 0.8 x {factor:.1f}", flying_ratio >= 0.8
        ),
        BenchResult(
            "run_cpu_s", cpu, "s", f"<= {RUN_OVER_DETACHED_TARGET:g} x detached_run_cpu_s", None
        ),
        BenchResult("vehicle_cpu_per_step_us", per_step, "us", "reference", None),
        BenchResult(
            "table3_wall_s_estimate", estimate, "s", f"<= {t3_target:.0f}", estimate <= t3_target
        ),
    ]


BENCHMARKS: dict[str, Callable[[], list[BenchResult]]] = {
    "world": bench_sigma0_map,
    "vehicle": lambda: bench_vehicle() + bench_vehicle_step(),
    "gcs": bench_ground_station,
    "margins": bench_margins,
    "roles": bench_roles,
    "integrity": bench_integrity,
    "multipath": bench_multipath,
    "run": bench_runs,
    "floor": bench_floor,
    "study": bench_studies,
    "view": bench_view,
}


def bench_machine_speed(repeats: int = 5) -> BenchResult:
    """CPU seconds of a fixed pure-Python loop: how fast this machine is right now (a shared
    VM's speed drifts by tens of per cent within hours, and every other row moves with it)."""
    return BenchResult("machine_python_loop_s", python_loop_s(repeats), "s", "reference", None)


def run_benchmarks(
    only: list[str] | None = None, progress: TextIO | None = None
) -> list[BenchResult]:
    """Run the chosen benchmark groups (all by default), after the machine's speed; each
    group's start and duration on ``progress`` (stderr by default: some take minutes)."""
    progress = progress or sys.stderr
    results: list[BenchResult] = [bench_machine_speed()]
    for name, bench in BENCHMARKS.items():
        if only is None or name in only:
            start = time.monotonic()
            progress.write(f"bench: {name} ...\n")
            progress.flush()
            results.extend(bench())
            progress.write(f"bench: {name} done in {time.monotonic() - start:.0f} s\n")
    return results + same_invocation_ratios(results)


def same_invocation_ratios(results: list[BenchResult]) -> list[BenchResult]:
    """Rows read against another of the same invocation, so that the machine's speed cancels
    out: a run's CPU over its decisions' alone (``--only run --only floor``), and a vehicle's
    step in a run over the same step warm (``--only run --only vehicle``)."""
    by_name = {result.name: result.value for result in results}
    rows = []
    if "run_cpu_s" in by_name and "detached_run_cpu_s" in by_name:
        ratio = by_name["run_cpu_s"] / by_name["detached_run_cpu_s"]
        target = RUN_OVER_DETACHED_TARGET
        rows.append(
            BenchResult(
                "run_over_detached_cpu_ratio", ratio, "x", f"<= {target:g}", ratio <= target
            )
        )
    if "vehicle_cpu_per_step_us" in by_name and "vehicle_step_warm_us" in by_name:
        ratio = by_name["vehicle_cpu_per_step_us"] / by_name["vehicle_step_warm_us"]
        rows.append(BenchResult("vehicle_run_over_warm_ratio", ratio, "x", "reference", None))
    return rows
