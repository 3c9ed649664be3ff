"""The ground-station process: links to every vehicle, missions, the run loop, logs.

Every packet received or sent goes to the tlog stamped with simulated time from the scenario's
epoch; the per-cycle record and snapshots of G are written alongside as the run goes.
"""

from __future__ import annotations

import functools
import json
import socket
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from ground_station.cycle import CycleOutput, Models, StationState, control_cycle
from ground_station.localizability import LocalizabilityMap
from ground_station.measurements import support_measurements
from ground_station.mission_client import MissionClient, MissionTransferError
from ground_station.support_mpc import SupportMpc
from ground_station.support_planning import HelperPlanner, LocalPlanner, MpcHelper
from ground_station.tlog import TlogWriter
from mission.link.impairment import LinkSettings
from mission.link.mavlink_udp import Address, MavlinkCodec, MessageQueue, UdpEndpoint
from mission.link.vehicle_identity import VehicleIdentity
from mission.link.waypoints import read_waypoints, row_position_enu
from mission.procs.atomic import write_text_atomically
from mission.procs.cli_common import freeze_startup_heap
from mission.world.frames import GeodeticFrame, enu_to_ned
from mission.world.model import World

GCS_SYSTEM_ID = 255
GCS_COMPONENT_ID = 190
POSITION_ONLY = 0b0000_1101_1111_1000
SNAPSHOT_EVERY = 20
GUIDED_AND_ARMED = (  # DO_SET_MODE custom mode 4 (GUIDED), then arm
    (mavlink2.MAV_CMD_DO_SET_MODE, (1, 4)),
    (mavlink2.MAV_CMD_COMPONENT_ARM_DISARM, (1,)),
)
COMMAND_TIMEOUT_WALL_S = 5.0  # a command is repeated until acknowledged, this long at most


@dataclass(frozen=True)
class PendingStep:
    """A step the vehicles were asked to make: its length and, in lockstep, the tick that
    started it (sent again to a vehicle whose telemetry does not arrive)."""

    step_s: float
    tick: Any | None = None


class StationError(RuntimeError):
    """The run cannot go on (a vehicle never appeared, refused its mission, ...)."""


@dataclass(frozen=True)
class StationConfig:
    """How this ground station runs."""

    adaptive: bool
    vehicles: dict[str, Address]
    waypoints_dir: Path
    out_dir: Path
    seed: int = 0
    speedup: float | None = None  # None: lockstep
    tlog_path: Path | None = None  # default: out_dir / "gcs.tlog"
    signing_key: bytes | None = None  # MAVLink 2 signing secret
    link: LinkSettings = field(default_factory=LinkSettings)  # loss and delay of what we send
    step_timeout_wall_s: float = 5.0
    late_grace_wall_s: float = 0.05  # lockstep: how long a late vehicle is waited for
    link_loss_s: float = 3.0  # simulated seconds of silence before a vehicle counts as lost
    connect_timeout_wall_s: float = 30.0
    mpc_helper: bool = False  # share the support MPCs with a helper process (second core)


@dataclass
class VehicleView:
    """What the ground station holds about one vehicle."""

    name: str
    system_id: int
    address: Address
    latest: dict[str, Any] = field(default_factory=dict)
    step_ms: int = -1
    heartbeat_wall: float = -1.0
    heard_s: float = 0.0  # simulated time of the last message from it
    lost: bool = False  # silent for link_loss_s: out of fusion and the MPCs
    late: bool = False  # missed the last lockstep marker: not waited for
    outbox: list[tuple[Any, bytes]] = field(default_factory=list)  # (message, packet) unsent
    last_batch: list[Any] = field(default_factory=list)  # the messages last sent together


class GroundStation:
    """Runs one mission over MAVLink and logs everything."""

    def __init__(self, world: World, config: StationConfig) -> None:
        self.world = world
        self.scenario = world.scenario
        self.config = config
        self.frame = GeodeticFrame(self.scenario.world.anchor)
        self.endpoint = UdpEndpoint(
            MavlinkCodec(GCS_SYSTEM_ID, GCS_COMPONENT_ID, config.signing_key),
            link=config.link,
            link_seed=config.seed * 1000 + GCS_SYSTEM_ID,
        )
        self.link_stats = {"lost_in": 0, "tick_resends": 0, "late_steps": 0}
        self._last_seq: dict[int, int] = {}
        # how long a lockstep tick waits for its marker before being sent again
        self.retry_wall_s = 0.02 + 2 * config.link.delay_ms / 1000.0
        self.queue = MessageQueue(self.endpoint)
        config.out_dir.mkdir(parents=True, exist_ok=True)
        self.tlog = TlogWriter(config.tlog_path or config.out_dir / "gcs.tlog")
        self.records = (config.out_dir / "records.jsonl").open("w", encoding="utf-8")
        self.snapshots = config.out_dir / "g"
        self.snapshots.mkdir(exist_ok=True)
        self.views = {
            name: VehicleView(name, VehicleIdentity.parse(name).system_id, _resolved(address))
            for name, address in config.vehicles.items()
        }
        self.by_system = {v.system_id: v for v in self.views.values()}
        self.sim_time_s = 0.0
        self.cycles = 0
        self.models: Models | None = None
        self._helper: MpcHelper | None = None

    # -- links ------------------------------------------------------------------------------
    @property
    def time_usec(self) -> int:
        """Simulated time from the scenario's epoch, for the tlog."""
        return round((self.scenario.run.epoch_unix_s + self.sim_time_s) * 1e6)

    def send(self, message: Any, view: VehicleView) -> None:
        """Send to one vehicle and log the packet."""
        packet = self.endpoint.send(message, [view.address])
        self.tlog.write(self.time_usec, packet)

    def queue_for(self, message: Any, view: VehicleView) -> None:
        """Log the packet now (its time and sequence number are now's) and send it with the
        vehicle's other packets of the cycle at :meth:`flush_outboxes`."""
        packet = self.endpoint.encode(message)
        self.tlog.write(self.time_usec, packet)
        view.outbox.append((message, packet))

    def flush_outboxes(self) -> None:
        """Each vehicle's queued packets out, in order, in one datagram (commands and tick
        wake a vehicle once, not three times)."""
        for view in self.views.values():
            self._flush(view)

    def _flush(self, view: VehicleView) -> None:
        if view.outbox:
            self.endpoint.send_packets([packet for _, packet in view.outbox], [view.address])
            view.last_batch = [message for message, _ in view.outbox]
            view.outbox = []

    def _log_received(self, message: Any, sender: Address) -> None:
        view = self.by_system.get(message.get_srcSystem())
        if view is None or sender != view.address:  # only our vehicles, from where they are
            self.endpoint.counters.reject("unknown sender")
            return
        self.tlog.write(self.time_usec, message.get_msgbuf())
        self._count_gap(view.system_id, message.get_seq())
        kind = message.get_type()
        view.latest[kind] = message
        view.heard_s = self.sim_time_s
        if kind == "HEARTBEAT":
            view.heartbeat_wall = time.monotonic()
        elif kind == "SYSTEM_TIME":
            view.step_ms = int(message.time_boot_ms)

    def _count_gap(self, system_id: int, seq: int) -> None:
        """Packets lost on the way in, from gaps in the sender's sequence numbers."""
        last = self._last_seq.get(system_id)
        if last is not None:
            gap = (seq - last - 1) % 256
            if gap < 128:  # larger: a repeat or reordering, not a loss
                self.link_stats["lost_in"] += gap
            else:
                return
        self._last_seq[system_id] = seq

    def pump(self, seconds: float, until: Callable[[], bool] | None = None) -> None:
        """Receive and log for up to ``seconds`` or until ``until()`` holds."""
        deadline = time.monotonic() + seconds
        while until is None or not until():
            got = self.queue.next(deadline - time.monotonic())
            if got is None:
                return
            self._log_received(*got)

    # -- set-up -----------------------------------------------------------------------------
    def connect(self) -> None:
        """Wait for every vehicle's heartbeat (announcing ourselves so they answer)."""
        beat = mavlink2.MAVLink_heartbeat_message(
            mavlink2.MAV_TYPE_GCS, mavlink2.MAV_AUTOPILOT_INVALID, 0, 0, 0, 3
        )
        deadline = time.monotonic() + self.config.connect_timeout_wall_s
        while time.monotonic() < deadline:
            for view in self.views.values():
                self.send(beat, view)
            self.pump(0.5, lambda: all(v.heartbeat_wall > 0 for v in self.views.values()))
            if all(v.heartbeat_wall > 0 for v in self.views.values()):
                return
        missing = [v.name for v in self.views.values() if v.heartbeat_wall < 0]
        raise StationError(f"no heartbeat from {', '.join(missing)}")

    def upload_missions(self) -> dict[str, np.ndarray]:
        """Upload each vehicle's waypoint file; return their waypoints (ENU, home excluded)."""
        waypoints = {}
        for view in self.views.values():
            rows = read_waypoints(self.config.waypoints_dir / f"{view.name}.waypoints")
            client = MissionClient(
                self.queue, view.address, view.system_id, on_other=self._log_received
            )
            client.on_sent = lambda packet: self.tlog.write(self.time_usec, packet)
            try:
                result = client.upload([row.to_item() for row in rows])
            except MissionTransferError as error:
                raise StationError(f"{view.name}: {error}") from None
            if result != mavlink2.MAV_MISSION_ACCEPTED:
                raise StationError(f"{view.name} refused its mission (MAV_MISSION_RESULT {result})")
            waypoints[view.name] = np.array([row_position_enu(r, self.frame) for r in rows[1:]])
        return waypoints

    def arm_all(self) -> None:
        """GUIDED and armed, each acknowledged."""
        for view in self.views.values():
            for command, params in GUIDED_AND_ARMED:
                deadline = time.monotonic() + COMMAND_TIMEOUT_WALL_S
                while not _acked(view, command) and time.monotonic() < deadline:
                    self._command_long(view, command, params)
                    self.pump(4 * self.retry_wall_s, lambda v=view, c=command: _acked(v, c))
                if not _acked(view, command):
                    raise StationError(f"{view.name} did not accept command {command}")
                view.latest.pop("COMMAND_ACK", None)

    # -- the run ----------------------------------------------------------------------------
    def run(self) -> dict[str, Any]:
        """Connect, upload, arm, then cycle until done or timeout; return a summary."""
        start_wall = time.monotonic()
        if self.config.mpc_helper:  # it imports while sigma_0 is computed here
            self._helper = MpcHelper(str(self.config.out_dir))
        sigma0 = self.world.sigma0_map().sigma_m
        if self._helper is not None:  # and builds its solver while we connect
            try:
                self._helper.set_up(self.scenario, sigma0)
            except OSError:
                print("ground station: MPC helper did not start; solving here", file=sys.stderr)
                self._helper.close()
                self._helper = None
        self.connect()
        waypoints = self.upload_missions()
        self.arm_all()
        models, state = self._initial(waypoints, sigma0)
        freeze_startup_heap()
        supports = [n for n in self.views if n != "work"]
        self._snapshot(models.g, "initial")
        self._last_seq.clear()  # count losses from here: set-up traffic is not all logged here
        self.link_stats["lost_in"] = 0
        completion = None
        pending = self._tick()
        self.flush_outboxes()
        while pending is not None:
            self._await_step(pending)
            self._check_links(state)
            measurements = support_measurements(
                [
                    (
                        name,
                        self._current(name, "GPS_RAW_INT"),
                        self._current(name, "LANDING_TARGET"),
                    )
                    for name in supports
                    if not self.views[name].lost
                ],
                self.world,
                self.frame,
            )
            work_step: list[PendingStep | None] = []
            send_work = functools.partial(self._command_work_first, state, work_step)
            output = control_cycle(state, measurements, models, send_work)
            self._command_supports(state, output)
            cycle_time_s = self.sim_time_s
            # the next tick goes out now: the vehicles step while this cycle is written down
            pending = None if state.completed else self._tick(*work_step)
            self.flush_outboxes()
            self._record(state, output, cycle_time_s)
            self.cycles += 1
            if self.cycles % SNAPSHOT_EVERY == 0:
                self._snapshot(models.g, f"{self.cycles:05d}")
            self.tlog.flush()
            if state.completed:
                completion = self.sim_time_s
                self._announce(f"Mission complete at {completion:.1f} s")
                break
        self._snapshot(models.g, "final")
        self.tlog.flush()
        self._write_link_stats()
        return {
            "completed": completion is not None,
            "completion_time_s": completion,
            "control_cycles": self.cycles,
            "sim_time_s": self.sim_time_s,
            "wall_time_s": time.monotonic() - start_wall,
        }

    def _write_link_stats(self) -> None:
        """link.json: what the links lost and how the lockstep recovered."""
        link = self.endpoint.link
        stats = {
            "loss": self.config.link.loss,
            "delay_ms": self.config.link.delay_ms,
            "sent_out": link.attempted if link is not None else None,
            "dropped_out": link.dropped if link is not None else 0,
            **self.link_stats,
            "rejected": dict(self.endpoint.counters.rejected),
        }
        write_text_atomically(self.config.out_dir / "link.json", json.dumps(stats) + "\n")

    def _initial(
        self, waypoints: dict[str, np.ndarray], sigma0: np.ndarray | None = None
    ) -> tuple[Models, StationState]:
        self.models, state = build_models(
            self.world, waypoints, self.config.adaptive, self.config.seed, self._helper, sigma0
        )
        return self.models, state

    def _next_step(self) -> PendingStep | None:
        """The next step, not started yet (None once the scenario's timeout is reached); in
        lockstep with the tick that will start it."""
        step = self.scenario.control.t_cont_s
        if self.sim_time_s >= self.scenario.run.timeout_s - 1e-9:
            return None
        if self.config.speedup is not None:
            return PendingStep(step)
        target_ms = round((self.sim_time_s + step) * 1000)
        usec = round((self.scenario.run.epoch_unix_s + target_ms / 1000.0) * 1e6)
        return PendingStep(step, mavlink2.MAVLink_system_time_message(usec, target_ms))

    def _tick(self, work_step: PendingStep | None = None) -> PendingStep | None:
        """Start the next step (None once the scenario's timeout is reached): in lockstep,
        advance the clock and queue every vehicle's tick after its commands (the work
        vehicle's only if it was not sent with its commands: ``work_step``); in real time the
        step just runs."""
        pending = self._next_step() if work_step is None else work_step
        if pending is None or pending.tick is None:
            return pending
        self.sim_time_s = pending.tick.time_boot_ms / 1000.0
        for view in self.views.values():
            if work_step is None or view.name != "work":
                self.queue_for(pending.tick, view)
        return pending

    def _await_step(self, pending: PendingStep) -> None:
        """Lockstep: wait for every vehicle's telemetry of the step, sending the tick again to
        a vehicle that stays behind. Real time: let the step's wall time pass."""
        tick = pending.tick
        if tick is None:
            self.pump(pending.step_s / self.config.speedup)
            self.sim_time_s += pending.step_s
            return
        target_ms = int(tick.time_boot_ms)
        awaited = [v for v in self.views.values() if not v.lost and not v.late]
        deadline = time.monotonic() + self.config.step_timeout_wall_s
        while True:
            self.pump(
                min(self.retry_wall_s, max(0.0, deadline - time.monotonic())),
                lambda: all(v.step_ms >= target_ms for v in awaited),
            )
            behind = [v for v in awaited if v.step_ms < target_ms]
            if not behind or time.monotonic() >= deadline:
                break
            for view in behind:  # the batch or the step's telemetry was lost: send it again
                for message in view.last_batch:  # encoded afresh: a signed link refuses replays
                    self.queue_for(message, view)
                self.link_stats["tick_resends"] += 1
            self.flush_outboxes()
        stragglers = [v for v in self.views.values() if v.step_ms < target_ms and not v.lost]
        if stragglers:
            self.pump(
                self.config.late_grace_wall_s,
                lambda: all(v.step_ms >= target_ms for v in stragglers),
            )
        for view in self.views.values():
            view.late = view.step_ms < target_ms
            self.link_stats["late_steps"] += int(view.late and not view.lost)

    def _check_links(self, state: StationState) -> None:
        """Drop a support that fell silent from fusion and the MPCs; take it back when heard."""
        for view in self.views.values():
            silent = self.sim_time_s - view.heard_s
            if not view.lost and silent >= self.config.link_loss_s - 1e-9:
                if view.name == "work":
                    raise StationError(f"work lost: no message for {silent:.1f} s")
                view.lost = True
                self._announce(f"{view.name} lost: silent {silent:.1f} s", to_log=True)
            elif view.lost and silent < self.scenario.control.t_cont_s - 1e-9:
                view.lost = False
                state.warm.pop(view.name, None)
                state.last_support_command.pop(view.name, None)
                self._rejoin(view)
                self._announce(f"{view.name} back", to_log=True)

    def _rejoin(self, view: VehicleView) -> None:
        """GUIDED and arm a vehicle that came back (its ACKs arrive with later steps)."""
        for command, params in GUIDED_AND_ARMED:
            self._command_long(view, command, params)

    def _command_long(self, view: VehicleView, command: int, params: tuple[float, ...]) -> None:
        values = [*params, *[0.0] * (7 - len(params))]
        self.send(
            mavlink2.MAVLink_command_long_message(view.system_id, 1, command, 0, *values), view
        )

    def _current(self, name: str, kind: str) -> Any | None:
        """The vehicle's message of this kind from the current step (None if late or missing)."""
        message = self.views[name].latest.get(kind)
        if message is None:
            return None
        if self.config.speedup is None:
            step_usec = self.time_usec
            if abs(int(message.time_usec) - step_usec) > 1000:
                return None
        return message

    def _command_work_first(
        self,
        state: StationState,
        started: list[PendingStep | None],
        command: np.ndarray,
        reached: int | None,
    ) -> None:
        """Send the work vehicle its estimate, setpoint (the next mission item once a waypoint
        is reached) and, unless the mission is complete, the next step's tick, before the
        support MPCs are solved: it steps meanwhile, and its truth is there when the supports
        step. The step its tick starts (None: no tick went out) goes into ``started``."""
        work = self.views["work"]
        self._estimate(state.xhat, work)
        self._setpoint(command, work)
        if reached is not None and not state.completed:
            self.queue_for(
                mavlink2.MAVLink_mission_set_current_message(work.system_id, 1, state.k + 1), work
            )
            self._announce(f"Work UAV reached waypoint {reached + 1}")
        step = None if state.completed else self._next_step()
        if step is not None and step.tick is not None:
            self.queue_for(step.tick, work)
        self._flush(work)
        started.append(step)

    def _command_supports(self, state: StationState, output: CycleOutput) -> None:
        for name, target in output.support_targets.items():
            self._estimate(state.yhat[name], self.views[name])
            self._setpoint(target, self.views[name])

    def _estimate(self, position: np.ndarray, view: VehicleView) -> None:
        n, e, d = (float(v) for v in enu_to_ned(position))
        self.queue_for(
            mavlink2.MAVLink_vision_position_estimate_message(self.time_usec, n, e, d, 0, 0, 0),
            view,
        )

    def _setpoint(self, target: np.ndarray, view: VehicleView) -> None:
        n, e, d = (float(v) for v in enu_to_ned(target))
        self.queue_for(
            mavlink2.MAVLink_set_position_target_local_ned_message(
                round(self.sim_time_s * 1000),
                view.system_id,
                1,
                mavlink2.MAV_FRAME_LOCAL_NED,
                POSITION_ONLY,
                n,
                e,
                d,
                0,
                0,
                0,
                0,
                0,
                0,
                0,
                0,
            ),
            view,
        )

    def _announce(self, text: str, to_log: bool = False) -> None:
        """A STATUSTEXT in the tlog (and on stderr for link events)."""
        if to_log:
            print(f"ground station: t={self.sim_time_s:.1f} s: {text}", file=sys.stderr, flush=True)
        message = mavlink2.MAVLink_statustext_message(
            mavlink2.MAV_SEVERITY_INFO, text.encode()[:50], 0, 0
        )
        self.tlog.write(self.time_usec, self.endpoint.send(message, []))

    def _record(self, state: StationState, output: CycleOutput, time_s: float) -> None:
        fusion = output.fusion
        record = {
            "t": round(time_s, 3),
            "k": state.k,
            "xhat": _round(state.xhat),
            "blind": fusion.blind,
            "fallback": fusion.fallback,
            "consistent": list(fusion.consistent),
            "contributing": list(fusion.contributing),
            "yhat": {n: _round(y) for n, y in state.yhat.items()},
            "beta": output.betas,
            "arrived": output.arrived,
            "g_updated_voxels": output.updated_voxels,
            "mpc": {
                n: {"status": p.status, "ms": round(p.solve_ms, 3), "resolved": p.resolved}
                for n, p in output.support_plans.items()
            },
            "cycle_ms": round(output.cycle_ms, 3),
        }
        self.records.write(json.dumps(record) + "\n")
        self.records.flush()

    def _snapshot(self, g: LocalizabilityMap, label: str) -> None:
        np.save(self.snapshots / f"G_{label}.npy", g.values)

    def close(self) -> None:
        """Stop the MPC helper; flush and close every file and the socket."""
        if self.models is not None:
            self.models.planner.close()
        elif self._helper is not None:
            self._helper.close()
        self.tlog.close()
        self.records.close()
        self.endpoint.close()


def _acked(view: VehicleView, command: int) -> bool:
    ack = view.latest.get("COMMAND_ACK")
    return ack is not None and ack.command == command and ack.result == 0


def _round(v: np.ndarray) -> list[float]:
    return [round(float(x), 4) for x in v]


def build_models(
    world: World,
    waypoints: dict[str, np.ndarray],
    adaptive: bool,
    seed: int,
    helper: MpcHelper | None = None,
    sigma0: np.ndarray | None = None,
) -> tuple[Models, StationState]:
    """Everything the control cycle needs, and the state at the start (vehicles at w_1);
    the support MPCs are shared with ``helper`` if one is given. ``sigma0`` is the world's
    sigma_0 map if already computed."""
    scn = world.scenario
    grid = world.map_grid()
    if sigma0 is None:
        sigma0 = world.sigma0_map().sigma_m
    g = LocalizabilityMap(grid, sigma0, scn.map, adaptive)
    supports = {n: w for n, w in waypoints.items() if n != "work"}
    mpc = SupportMpc(scn.control, grid, world.camera, g.initial)
    observable = world.camera.observable
    models = Models(
        scn,
        world,
        waypoints["work"],
        supports,
        g,
        mpc,
        np.random.default_rng(seed),
        LocalPlanner(mpc, observable) if helper is None else HelperPlanner(mpc, observable, helper),
    )
    state = StationState(
        xhat=waypoints["work"][0].copy(),
        yhat={n: w[0].copy() for n, w in supports.items()},
        k=min(1, len(waypoints["work"]) - 1),
    )
    return models, state


def _resolved(address: Address) -> Address:
    """(IP, port): replies come from an IP address, so names are looked up once here."""
    host, port = address
    try:
        return socket.gethostbyname(host), port
    except OSError:
        raise StationError(f"cannot resolve vehicle host {host!r}") from None
