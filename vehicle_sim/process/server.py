"""The vehicle process: sockets, peers, the simulation clock and the truth channel.

Stepping lives in :class:`~vehicle_sim.vehicle.Vehicle`; this module only decides *when* to step
(BlueSky's split between simulation and pacing):

- lockstep: the ground station is the master clock. A SYSTEM_TIME from it (time_boot_ms = T)
  means "advance to T"; a vehicle started into a running mission takes up the clock from its
  first tick. With no tick for ``lockstep_timeout_wall_s`` the vehicle advances one
  step alone, so a lost packet cannot freeze it; before the first tick it only sends heartbeats.
- real time: one step every ``t_cont / speedup`` wall seconds, on the host's common beat
  (:mod:`mission.procs.wall_grid`: every vehicle samples at the same instants); the vehicle's
  simulated clock is its own (it counts from its start, as an autopilot's time since boot),
  and it answers TIMESYNC with it so the ground station can map its stamps onto its clock.

Each step ends with SYSTEM_TIME (the step marker the ground station waits for). A support's
camera sample of a step needs the work UAV's truth at the same physical time
(:mod:`vehicle_sim.process.truth_link`); it is waited for briefly: in lockstep up to
``truth_timeout_wall_s``, in real time up to one step's wall time (then interpolated). In
lockstep, after a wait that timed out, none is waited for again until a newer truth arrives
(a frozen work UAV would otherwise cost every step the timeout).
"""

from __future__ import annotations

import contextlib
import math
import os
import select
import sys
import time
import traceback
from dataclasses import dataclass
from typing import Any

from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.link.mavlink_udp import Address, UdpEndpoint
from mission.link.vehicle_identity import VehicleIdentity
from mission.procs.wall_grid import next_grid_instant
from vehicle_sim.process.signals import signal_wakeup
from vehicle_sim.process.truth_link import TruthReceiver, TruthSender
from vehicle_sim.vehicle import Vehicle

PEER_EXPIRY_WALL_S = 30.0
MAX_WAIT_WALL_S = 0.1
IDLE_HEARTBEAT_WALL_S = 1.0
MAX_TICK_JUMP_S = 60.0  # a clock tick may advance at most this far (guards against garbage)
MAX_JOIN_S = 1e6  # s: a run joined later than 11 days in is no run (2^32 ms is 49 days)


@dataclass(frozen=True)
class ClockSettings:
    """How simulated time advances."""

    lockstep: bool
    speedup: float = 1.0


@dataclass
class ServerStats:
    """What the process reports at exit."""

    auto_steps: int = 0
    truth_waits_timed_out: int = 0
    resent_steps: int = 0


class VehicleServer:
    """Runs one vehicle: receives, steps, publishes until asked to stop."""

    def __init__(
        self,
        endpoint: UdpEndpoint,
        outs: list[Address],
        clock: ClockSettings,
        truth_sender: TruthSender | None = None,
        truth_receiver: TruthReceiver | None = None,
        exit_with_parent: bool = False,
    ) -> None:
        self.endpoint = endpoint
        self.outs = list(outs)
        self.clock = clock
        self.truth_sender = truth_sender
        self.truth_receiver = truth_receiver
        self.exit_with_parent = exit_with_parent
        self.peers: dict[Address, float] = {}
        self.stats = ServerStats()
        self.vehicle: Vehicle | None = None
        self.stopping = False
        self._requested_s = 0.0
        self._started = False
        self._last_tick_wall = 0.0
        self._origin_wall = 0.0
        self._origin_unix = 0.0  # the same instant on the host's wall clock (truth channel)
        self._last_idle_heartbeat = -math.inf
        self._pending_deadline: float | None = None
        self._gave_up_at: int | None = None  # the newest truth when a wait last timed out
        self._parent = os.getppid()
        self._batch: list[Any] | None = None
        self._step_events: list[Any] | None = None  # collecting what the vehicle says as it steps
        self._said: list[Any] = []  # what the step said, sent with its telemetry
        # The last step's messages, for a repeated tick: encoded afresh when asked again, since
        # a signed link refuses a replayed packet (its signature timestamp must increase).
        self._last_step: list[Any] = []
        self._reported_errors: set[str] = set()  # handler errors already logged in full

    def attach(self, vehicle: Vehicle) -> None:
        """Connect the vehicle whose messages this server carries."""
        self.vehicle = vehicle

    def broadcast(self, message: Any) -> None:
        """Send a message to every peer that has talked to us and every --out address.

        While a step is being published, messages are collected and leave together; what the
        vehicle says while it steps (faults, parameters, contacts) leaves with that step's
        telemetry, beside its marker, so that it is as reliable as the lockstep: a step whose
        marker was lost is sent again, and carries it again.
        """
        if self._step_events is not None:
            self._step_events.append(message)
        elif self._batch is not None:
            self._batch.append(message)
        else:
            self.endpoint.send(message, [*self.peers, *self.outs])

    def _publish_step(self, truth: Any) -> None:
        """Publish the step's telemetry as one batch of datagrams."""
        assert self.vehicle is not None
        said, self._said, self._batch = self._said, [], []
        try:
            self.vehicle.publish(truth)
        finally:
            # What the step said goes just before the marker (SYSTEM_TIME, the last): in the
            # marker's datagram, so that a marker received means they were received.
            batch, self._batch = self._batch[:-1] + said + self._batch[-1:], None
            self.endpoint.send_many(batch, [*self.peers, *self.outs])
            self._last_step = batch

    # -- main loop --------------------------------------------------------------------------
    def run(self) -> None:
        """Serve until stop() or a signal."""
        assert self.vehicle is not None
        self._origin_wall, self._origin_unix = time.monotonic(), time.time()
        if not self.clock.lockstep:  # steps on the host's common beat (sensors on a PPS)
            step_wall = self.vehicle.clock.step_s / self.clock.speedup
            self._origin_wall, self._origin_unix = next_grid_instant(step_wall)
        sources: list[Any] = [self.endpoint]
        if self.truth_receiver is not None:
            sources.append(self.truth_receiver)
        with signal_wakeup() as woken:  # a signal ends the wait at once, not at the timeout
            sources.append(woken)
            self._serve(sources)

    def _serve(self, sources: list[Any]) -> None:
        assert self.vehicle is not None
        woken = sources[-1]
        # The other vehicles' truths are read when a step needs them; only a step waiting for
        # the work UAV's truth is woken by one (else each truth would wake every vehicle).
        unless_waiting = [source for source in sources if source is not self.truth_receiver]
        while not self.stopping:
            now = time.monotonic()
            wait = max(0.0, min(MAX_WAIT_WALL_S, self._next_deadline(now) - now))
            polled = sources if self._pending_deadline is not None else unless_waiting
            readable, _, _ = select.select(polled, [], [], wait)
            now = time.monotonic()
            if woken in readable:
                with contextlib.suppress(OSError):
                    woken.recv(256)
            if self.truth_receiver is not None and self.truth_receiver in readable:
                self.truth_receiver.drain()
            if self.endpoint in readable:
                for message, sender in self.endpoint.receive():
                    self._on_message(message, sender, now)
            self.vehicle.mission.tick(now)
            self._advance(now)
            self._idle_heartbeat(now)
            self._expire_peers(now)
            if self.exit_with_parent and os.getppid() != self._parent:
                self.stopping = True

    def stop(self, *_: Any) -> None:
        """Ask the loop to finish (signal handler)."""
        self.stopping = True

    def _next_deadline(self, now: float) -> float:
        vehicle = self.vehicle
        assert vehicle is not None
        if self._pending_deadline is not None:
            return min(self._pending_deadline, now + 0.005)
        if self.clock.lockstep:
            if self._started and self._requested_s > vehicle.sim_time_s + 1e-9:
                return now
            if self._started:
                return self._last_tick_wall + vehicle.scenario.vehicle.lockstep_timeout_wall_s
            return self._last_idle_heartbeat + IDLE_HEARTBEAT_WALL_S
        step_wall = vehicle.clock.step_s / self.clock.speedup
        return self._origin_wall + (vehicle.clock.steps + 1) * step_wall

    def _on_message(self, message: Any, sender: Address, now: float) -> None:
        vehicle = self.vehicle
        assert vehicle is not None
        if message.get_srcSystem() == vehicle.identity.system_id:
            return  # our own echo (e.g. through a mirror)
        if sender not in self.peers:
            self._last_idle_heartbeat = -math.inf  # a new peer hears from us at once
        self.peers[sender] = now
        if message.get_type() == "SYSTEM_TIME":
            if self.clock.lockstep:
                self._on_tick(message.time_boot_ms / 1000.0, now, sender)
            return
        if message.get_type() == "TIMESYNC" and not self.clock.lockstep:
            self._on_timesync(message, now)
            return
        try:
            vehicle.handle(message, now)
        except Exception as error:  # a malformed message never kills the vehicle
            kind = f"handler error {type(error).__name__}"
            if kind not in self._reported_errors:  # the first of each kind, with where it was
                self._reported_errors.add(kind)
                print(f"vehicle: {message.get_type()} raised (first of its kind, counted):",
                      file=sys.stderr)  # fmt: skip
                traceback.print_exc()
            vehicle.counters.reject(kind)

    def _on_tick(self, time_s: float, now: float, sender: Address) -> None:
        """The ground station's clock: advance to ``time_s`` (bounded jumps only). A tick for
        the step just published asks for its telemetry again (its datagrams were lost)."""
        vehicle = self.vehicle
        assert vehicle is not None
        if self._last_step and abs(time_s - vehicle.sim_time_s) < 1e-9:
            if self._pending_deadline is None:
                self.endpoint.send_many(self._last_step, [sender])
                self.stats.resent_steps += 1
            return
        if not self._started and vehicle.clock.steps == 0 and time_s > vehicle.clock.step_s + 1e-9:
            if time_s > MAX_JOIN_S:  # SYSTEM_TIME's time_boot_ms (uint32 ms) would overflow
                vehicle.counters.reject("clock tick too far ahead")
                return
            vehicle.join_clock(time_s)  # a vehicle (re)started into a running mission
        if not 0 < time_s - vehicle.sim_time_s <= MAX_TICK_JUMP_S:
            if time_s > vehicle.sim_time_s:
                vehicle.counters.reject("clock tick too far ahead")
            return
        self._requested_s = max(self._requested_s, time_s)
        self._started = True
        self._last_tick_wall = now

    def _on_timesync(self, message: Any, now: float) -> None:
        """Real time: answer a TIMESYNC request with this vehicle's clock now (not the last
        step's time: the ground station's offset estimate needs the instant of the reply)."""
        if message.tc1 != 0:
            return
        vehicle = self.vehicle
        assert vehicle is not None
        now_ns = round((now - self._origin_wall) * self.clock.speedup * 1e9)
        vehicle.send(mavlink2.MAVLink_timesync_message(now_ns, message.ts1))

    def _physical_usec(self, steps_back: int = 0) -> int:
        """The physical time of the current step (or of one ``steps_back`` before it) for the
        truth channel: simulated time in lockstep, the host's wall clock at the step's nominal
        instant in real time."""
        vehicle = self.vehicle
        assert vehicle is not None
        steps = vehicle.clock.steps - steps_back
        if self.clock.lockstep:
            return round(steps * vehicle.clock.step_s * 1e6)
        step_wall = vehicle.clock.step_s / self.clock.speedup
        return round((self._origin_unix + steps * step_wall) * 1e6)

    def _others_last_step(self) -> dict[str, tuple[Any, Any]] | None:
        """Each other vehicle's true motion over the step just ended (for contact), from the
        truth channel: in lockstep every vehicle's truth of that step is in before the tick
        that starts this one (it left before the vehicle's step marker)."""
        receiver, vehicle = self.truth_receiver, self.vehicle
        assert vehicle is not None
        if receiver is None or vehicle.clock.steps == 0:
            return None
        receiver.drain()
        motions = receiver.motions(self._physical_usec(1), self._physical_usec())
        return {VehicleIdentity.from_system_id(s).name: m for s, m in motions.items()}

    def _truth_wait_wall_s(self) -> float:
        """How long a support waits for the work UAV's truth of its step."""
        vehicle = self.vehicle
        assert vehicle is not None
        timeout = vehicle.scenario.vehicle.truth_timeout_wall_s
        if self.clock.lockstep:
            return timeout
        return min(timeout, vehicle.clock.step_s / self.clock.speedup)

    # -- stepping ---------------------------------------------------------------------------
    def _advance(self, now: float) -> None:
        vehicle = self.vehicle
        assert vehicle is not None
        if self._pending_deadline is not None and not self._finish_pending(now):
            return
        if self.clock.lockstep:
            if not self._started:
                return
            timeout = vehicle.scenario.vehicle.lockstep_timeout_wall_s
            idle = self._requested_s <= vehicle.sim_time_s + 1e-9
            if idle and now - self._last_tick_wall > timeout:
                self._requested_s = vehicle.sim_time_s + vehicle.clock.step_s
                self._last_tick_wall = now
                self.stats.auto_steps += 1
            while self._requested_s > vehicle.sim_time_s + 1e-9:
                if not self._do_step(now):
                    return
        else:
            due = math.floor(
                (now - self._origin_wall) * self.clock.speedup / vehicle.clock.step_s + 1e-9
            )
            while vehicle.clock.steps < due:
                if not self._do_step(now):
                    return

    def _do_step(self, now: float) -> bool:
        """One step; False if its publication waits for the work UAV's truth."""
        vehicle = self.vehicle
        assert vehicle is not None
        self._step_events = []
        try:
            vehicle.step(self._others_last_step())
        finally:
            self._said, self._step_events = self._step_events, None
        physical_usec = self._physical_usec()
        if self.truth_sender is not None:
            self.truth_sender.publish(vehicle.kinematics.truth, physical_usec)
        if self.truth_receiver is None or vehicle.identity.is_work or not vehicle.sensor_due():
            self._publish_step(None)
            return True
        self.truth_receiver.drain()
        truth = self.truth_receiver.exact(physical_usec)
        receiver = self.truth_receiver
        silent = self._gave_up_at is not None and self._gave_up_at == receiver.newest_usec()
        if truth is None and receiver.may_still_come(physical_usec) and not silent:
            self._pending_deadline = now + self._truth_wait_wall_s()
            return False
        self._publish_step(
            truth if truth is not None else self.truth_receiver.estimate(physical_usec)
        )
        return True

    def _finish_pending(self, now: float) -> bool:
        vehicle, receiver = self.vehicle, self.truth_receiver
        assert vehicle is not None and receiver is not None and self._pending_deadline is not None
        physical_usec = self._physical_usec()
        truth = receiver.exact(physical_usec)
        timed_out = now >= self._pending_deadline
        if truth is None and not timed_out and receiver.may_still_come(physical_usec):
            return False
        if truth is None:  # a later truth came instead, or none in time
            self.stats.truth_waits_timed_out += int(timed_out)
            if timed_out and self.clock.lockstep:  # not waited for again until the work UAV
                self._gave_up_at = receiver.newest_usec()  # is heard from (its 10 s a step)
            truth = receiver.estimate(physical_usec)
        self._pending_deadline = None
        self._publish_step(truth)
        return True

    def _idle_heartbeat(self, now: float) -> None:
        if (
            self.clock.lockstep
            and not self._started
            and now - self._last_idle_heartbeat >= IDLE_HEARTBEAT_WALL_S
        ):
            assert self.vehicle is not None
            self.broadcast(self.vehicle.heartbeat())
            if self.truth_sender is not None:  # lets the supports know a work UAV exists
                self.truth_sender.publish(self.vehicle.kinematics.truth, 0)
            self._last_idle_heartbeat = now

    def _expire_peers(self, now: float) -> None:
        for peer, seen in list(self.peers.items()):
            if now - seen > PEER_EXPIRY_WALL_S:
                del self.peers[peer]

    def summary(self) -> str:
        """One line for the log at exit."""
        vehicle = self.vehicle
        assert vehicle is not None
        receiver = self.truth_receiver
        between, beyond = (receiver.interpolated, receiver.extrapolated) if receiver else (0, 0)
        return (
            f"{vehicle.identity.name}: {vehicle.clock.steps} steps to "
            f"t={vehicle.sim_time_s:.1f} s; "
            f"link {self.endpoint.summary()}; vehicle rejected: "
            f"{dict(sorted(vehicle.counters.rejected.items())) or 'none'}; "
            f"auto steps {self.stats.auto_steps}, truth waits timed out "
            f"{self.stats.truth_waits_timed_out}, truth interpolated {between}, extrapolated "
            f"{beyond}, "
            f"steps resent {self.stats.resent_steps}"
        )
