"""``mission run``: one process per vehicle and a ground station, on free loopback ports.

The ground station is forked first (:mod:`mission.procs.forked`) and imports its own code; meanwhile
this process imports the vehicle simulator once and forks the four vehicles. Where forking is
not safe, or ``process_start="exec"`` asks for it, each is started as ``python -m
ground_station`` or ``python -m vehicle_sim`` instead. Either way the results are the same.

Children write their stderr to ``DIR/<name>.log``; all of them are stopped when the run ends,
fails, or is interrupted, and die with this process if it is killed (``--exit-with-parent``).
"""

from __future__ import annotations

import errno
import json
import os
import re
import socket
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, Protocol

from mission.analysis.lockstep import lockstep_integrity
from mission.analysis.run_metrics import run_metrics
from mission.config.errors import InputError
from mission.config.run_outputs import G_SNAPSHOTS, GSnapshots
from mission.config.settings import Scenario
from mission.link.impairment import LinkSettings
from mission.link.plan_files import vehicle_names
from mission.procs.atomic import write_text_atomically
from mission.procs.disk_full import EXIT_NO_SPACE
from mission.procs.forked import ForkedProcess, fork_is_safe, start_forked
from mission.procs.interrupts import StopRequest
from mission.procs.process_life import child_environment
from mission.procs.provenance import run_provenance
from mission.procs.stopping import stop_processes
from mission.runs.compile_relay import CompileRelay, compile_summary
from mission.runs.progress import RunProgress
from mission.runs.stall import DEFAULT_STALL_S, StallWatch

_BANNER = re.compile(r"listening on [\d.]+:(\d+)")
SUPERVISE_S = 0.1  # how often the vehicles are checked while the ground station runs


class RunFailed(RuntimeError):
    """A child process died or a run could not start; names the process."""


@dataclass(frozen=True)
class RunOptions:
    """What to run and where."""

    scenario: str
    method: str
    seed: int
    out_dir: Path
    speedup: float | None = None
    signing_key: Path | None = None  # the key file, passed to every process
    observer: str | None = None  # HOST:PORT every vehicle also streams to
    link: LinkSettings = field(default_factory=LinkSettings)  # impairment of every link
    mpc_helper: bool | None = None  # the ground station's MPC helper (None: its default)
    process_start: Literal["fork", "exec"] = "fork"  # fork: where safe, else exec
    g_snapshots: GSnapshots = "every"  # the ground station's G snapshots
    stall_s: float = DEFAULT_STALL_S  # wall seconds without progress that stop it (0: never)

    def __post_init__(self) -> None:
        if not (self.stall_s >= 0 and self.stall_s != float("inf")):
            raise ValueError(f"stall_s must be finite and >= 0, not {self.stall_s!r}")
        if self.process_start not in ("fork", "exec"):
            raise ValueError(f"process_start must be fork or exec, not {self.process_start!r}")
        if self.g_snapshots not in G_SNAPSHOTS:
            raise ValueError(f"g_snapshots must be one of {G_SNAPSHOTS}, not {self.g_snapshots!r}")


class RunWatcher(Protocol):
    """Something that follows the run's folder while it runs (the live view)."""

    def poll(self) -> None: ...

    def finish(self) -> None: ...


@dataclass
class Child:
    """A started child process and its log."""

    name: str
    process: subprocess.Popen | ForkedProcess
    log: Path


def run_mission(
    options: RunOptions, scenario: Scenario, watcher: RunWatcher | None = None
) -> dict[str, Any]:
    """Run a mission to completion or timeout; return its summary (also in summary.json).
    ``watcher`` is polled while the ground station runs, and finished once it has."""
    options.out_dir.mkdir(parents=True, exist_ok=True)
    children: list[Child] = []
    start = time.monotonic()
    # Ctrl-C and SIGTERM stop the run, even where the caller started it with SIGINT ignored
    # (a background job): its forked children take Python's default handlers back.
    with StopRequest() as stop:
        try:
            try:
                gcs = _start_processes(options, scenario, children)
                stall = StallWatch(options.out_dir / "gcs.tlog", options.stall_s)
                progress = None
                if RunProgress.wanted():
                    records = options.out_dir / "records.jsonl"
                    progress = RunProgress(records, scenario.run.timeout_s)
                _supervise(gcs, children, {"work"}, watcher, stop, stall, progress)
                if gcs.process.returncode == EXIT_NO_SPACE:  # its files could not be written
                    full = errno.ENOSPC
                    raise OSError(full, os.strerror(full), str(options.out_dir / "gcs.tlog"))
                if gcs.process.returncode != 0:
                    status = gcs.process.returncode
                    raise RunFailed(f"ground_station exited with status {status}{_why(gcs.log)}")
            finally:
                _stop_all(children)
        except RunFailed as failure:  # what the run got to, and why it ended, is kept
            stop.check()  # unless it was cancelled: then it is not a result of any kind
            _write_failed_summary(options, scenario, time.monotonic() - start, str(failure))
            raise
        stop.check()  # a request whose exception was swallowed: the run was cancelled
    if watcher is not None:
        watcher.finish()
    summary = _summary(options, scenario, time.monotonic() - start)
    if options.speedup is None:
        vehicles = {c.name: c.log for c in children if c.name != "ground_station"}
        summary["lockstep"] = lockstep_integrity(vehicles, summary.get("link"))
    summary["cpu_s"] = _cpu_seconds(children)
    write_text_atomically(options.out_dir / "summary.json", json.dumps(summary, indent=2) + "\n")
    return summary


def _cpu_seconds(children: list[Child]) -> dict[str, float]:
    """User + system CPU seconds of each forked process of the run (the ground station's with
    its MPC helper's) and of this one so far (start-up, the run, the analysis); a process
    started with ``--process-start exec`` is not counted (its rusage is not kept)."""
    import resource

    usage = resource.getrusage(resource.RUSAGE_SELF)
    cpu = {"orchestrator": round(usage.ru_utime + usage.ru_stime, 3)}
    for child in children:
        used = getattr(child.process, "cpu_s", None)
        if used is not None:
            cpu[child.name] = round(used, 3)
    return cpu


def _why(log: Path) -> str:
    """': <the ground station's last word> (see LOG)', or ' (see LOG)'."""
    try:
        lines = log.read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError:
        lines = []
    said = [line.split(": ", 1)[1] for line in lines if line.startswith("ground station: ")]
    return f": {said[-1]} (see {log})" if said else f" (see {log})"


def _write_failed_summary(
    options: RunOptions, scenario: Scenario, wall: float, reason: str
) -> None:
    """summary.json of a run that failed: the tlog's metrics as far as it got (none if it
    holds nothing readable), and ``failed``: why."""
    try:
        summary = _summary(options, scenario, wall)
    except (InputError, ValueError, OSError):  # nothing readable recorded
        summary = {"scenario": scenario.name, "method": options.method, "seed": options.seed}
    summary["failed"] = reason
    write_text_atomically(options.out_dir / "summary.json", json.dumps(summary, indent=2) + "\n")


def _common_arguments(options: RunOptions) -> list[str]:
    """The arguments every process of the run gets."""
    pacing = ["--speedup", str(options.speedup)] if options.speedup else []
    if options.signing_key is not None:
        pacing += ["--signing-key", str(options.signing_key)]
    if options.link.impaired:
        pacing += ["--link-loss", str(options.link.loss)]
        pacing += ["--link-delay-ms", str(options.link.delay_ms)]
    return ["--scenario", options.scenario, "--seed", str(options.seed), *pacing]


def _start_processes(options: RunOptions, scenario: Scenario, children: list[Child]) -> Child:
    """The ground station, then every vehicle, each added to ``children`` as it starts;
    returns the ground station."""
    common = [*_common_arguments(options), "--exit-with-parent"]
    observer = ["--out", options.observer] if options.observer else []
    names = vehicle_names(scenario.task.supports)
    # Every socket is bound here and inherited, so the ground station starts first knowing
    # every address, before any vehicle has printed its banner.
    sockets = {name: _bound_udp() for name in names}
    truth_sockets = {name: _bound_udp() for name in names}  # each vehicle's, for the others
    addresses = ",".join(f"{n}={_address_of(sockets[n])}" for n in names)
    helper = [] if options.mpc_helper is None else [_flag("mpc-helper", options.mpc_helper)]
    forking = options.process_start == "fork" and fork_is_safe()
    station = ["--method", options.method, "--vehicles", addresses]
    station += ["--out", str(options.out_dir), "--g-snapshots", options.g_snapshots]
    station += [*helper, *common]
    gcs_main = _ground_station_main if forking else None
    gcs = _launch(options.out_dir, "ground_station", station, (), gcs_main)
    children.append(gcs)
    vehicle_main = _vehicle_main(scenario) if forking else None
    for name in names:
        fds = [sockets[name].fileno(), truth_sockets[name].fileno()]
        arguments = ["--vehicle", name, "--socket-fd", str(fds[0])]
        arguments += ["--truth-socket-fd", str(fds[1])]
        for other in names:
            if other != name:
                arguments += ["--truth-out", _address_of(truth_sockets[other])]
        arguments += [*observer, *common]
        children.append(_launch(options.out_dir, name, arguments, fds, vehicle_main))
    for sock in (*sockets.values(), *truth_sockets.values()):
        sock.close()  # the children hold them now
    return gcs


def _summary(options: RunOptions, scenario: Scenario, wall: float) -> dict[str, Any]:
    """summary.json: who ran, the tlog's metrics, wall time and the links' statistics."""
    summary = {
        "scenario": scenario.name,
        "scenario_source": scenario.source,
        "method": options.method,
        "seed": options.seed,
        "speedup": options.speedup,  # None: lockstep
        **run_metrics(options.out_dir / "gcs.tlog", scenario),
        "provenance": run_provenance(),
    }
    simulated = (summary["control_cycles"] or 0) * scenario.control.t_cont_s
    summary["wall_time_s"] = round(wall, 3)
    compiled = compile_summary(options.out_dir / "ground_station.log")
    compile_s = round(sum(compiled.values()), 1)
    if compiled:  # a first run on this machine compiled the MPC: not the run's pace
        summary["compile_s"] = compile_s
        summary["compiled"] = compiled
    flying = wall - compile_s
    summary["realtime_factor"] = round(simulated / flying, 3) if flying > 0 else None
    link_file = options.out_dir / "link.json"
    if link_file.is_file():
        summary["link"] = json.loads(link_file.read_text())
    return summary


def _vehicle_main(scenario: Scenario) -> Callable[[list[str]], int]:
    """The vehicles' entry point, imported here once for the four forks; with flying vehicles
    also their dynamics (casadi and the flight code), which each would otherwise import for
    itself, four at once on two cores."""
    from vehicle_sim.cli import entry_point

    if scenario.vehicle.dynamics == "multicopter":
        import vehicle_sim.dynamics.multicopter  # noqa: F401

    return entry_point


def _ground_station_main(argv: list[str]) -> int:
    """The forked ground station: it imports its own code (casadi and the MPCs), while this
    process goes on to the vehicles."""
    from ground_station.cli import entry_point

    return entry_point(argv)


def _flag(name: str, on: bool) -> str:
    """--NAME or --no-NAME."""
    return f"--{name}" if on else f"--no-{name}"


def _bound_udp() -> socket.socket:
    """A UDP socket bound to a free loopback port."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    return sock


def _address_of(sock: socket.socket) -> str:
    host, port = sock.getsockname()[:2]
    return f"{host}:{port}"


def _launch(
    out_dir: Path,
    name: str,
    arguments: list[str],
    pass_fds: Sequence[int],
    forked_main: Callable[[list[str]], int] | None,
) -> Child:
    """Start the ground station or a vehicle (``name``) with ``arguments``: forked to run
    ``forked_main``, or, without one, as ``python -m <its package>``."""
    log = out_dir / f"{name}.log"
    if forked_main is not None:
        forked = start_forked(forked_main, arguments, log, pass_fds, child_environment())
        return Child(name, forked, log)
    module = "ground_station" if name == "ground_station" else "vehicle_sim"
    handle = log.open("w")
    process = subprocess.Popen(
        [sys.executable, "-m", module, *arguments],
        stdout=handle,
        stderr=handle,
        stdin=subprocess.DEVNULL,
        env=child_environment(),
        pass_fds=tuple(pass_fds),
    )
    handle.close()
    return Child(name, process, log)


def _supervise(
    gcs: Child,
    children: list[Child],
    required: set[str],
    watcher: RunWatcher | None,
    stop: StopRequest,
    stall: StallWatch | None = None,
    progress: RunProgress | None = None,
) -> None:
    """Wait for the ground station; a dead required vehicle, or one that never started,
    ends the run with an error, and so does a stall (``stall``: its tlog has not grown for
    its limit). What the ground station says of a first run's compilation is shown as it
    comes, and on a terminal how far the run has got (``progress``); the watcher is polled."""
    relay = CompileRelay(gcs.log)
    try:
        _watch(gcs, children, required, watcher, stop, stall, relay, progress)
    finally:
        if progress is not None:
            progress.clear()


def _watch(gcs, children, required, watcher, stop, stall, relay, progress) -> None:
    """:func:`_supervise`'s loop."""
    while True:
        stop.check()
        try:
            gcs.process.wait(timeout=SUPERVISE_S)
            relay.poll()
            return
        except subprocess.TimeoutExpired:
            relay.poll()
            if progress is not None:
                progress.poll()
            if watcher is not None:
                watcher.poll()
        if stall is not None and stall.stalled(paused=relay.compiling):
            raise RunFailed(
                f"stalled: {stall.progress.name} did not grow for {stall.limit_s:g} s of wall "
                f"time{_why(gcs.log)}"
            )
        for child in children:
            if child is gcs or child.process.poll() is None:
                continue
            if not _BANNER.search(child.log.read_text()):
                tail = child.log.read_text().strip().splitlines()[-1:] or ["no output"]
                raise RunFailed(f"{child.name} did not start: {tail[0]}")
            if child.name in required:
                raise RunFailed(
                    f"{child.name} died (exit status {child.process.returncode}, see {child.log})"
                )


def _stop_all(children: list[Child]) -> None:
    stop_processes((child.process for child in children), grace_s=10.0)
