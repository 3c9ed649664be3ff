"""The vehicle process: sockets, peers, the simulation clock and the truth channel.

Stepping lives in :class:`~vehicle_sim.vehicle.Vehicle`; this module only decides *when* to step,
by the vehicle's :class:`~vehicle_sim.process.pacing.Pacing` (lockstep or real time), and
sends what it says through its :class:`~vehicle_sim.process.outbox.Outbox`.

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
from vehicle_sim.process.outbox import Outbox
from vehicle_sim.process.pacing import MAX_JOIN_S, ClockSettings, Pacing
from vehicle_sim.process.signals import signal_wakeup
from vehicle_sim.process.truth_link import TruthReceiver, TruthSender
from vehicle_sim.vehicle import Vehicle

MAX_WAIT_WALL_S = 0.1
PENDING_POLL_WALL_S = 0.005  # while a step waits for the work UAV's truth


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
        self.outbox = Outbox(endpoint, outs)
        self.clock = clock
        self.truth_sender = truth_sender
        self.truth_receiver = truth_receiver
        self.exit_with_parent = exit_with_parent
        self.stats = ServerStats()
        self.vehicle: Vehicle | None = None
        self.pacing: Pacing | None = None
        self.stopping = False
        self._pending_deadline: float | None = None
        self._gave_up_at: int | None = None  # the newest truth when a wait last timed out
        self._parent = os.getppid()
        self._reported_errors: set[str] = set()  # handler errors already logged in full

    def attach(self, vehicle: Vehicle) -> None:
        """Connect the vehicle whose messages this server carries, and pace its clock."""
        self.vehicle = vehicle
        timeout = vehicle.scenario.vehicle.lockstep_timeout_wall_s
        self.pacing = Pacing(self.clock, vehicle.clock, timeout)

    def _attached(self) -> tuple[Vehicle, Pacing]:
        assert self.vehicle is not None and self.pacing is not None
        return self.vehicle, self.pacing

    # -- main loop --------------------------------------------------------------------------
    def run(self) -> None:
        """Serve until stop() or a signal."""
        self._attached()[1].start()
        sources: list[Any] = [self.endpoint]
        if self.truth_receiver is not None:
            sources.append(self.truth_receiver)
        with signal_wakeup() as woken:  # a signal ends the wait at once, not at the timeout
            sources.append(woken)
            self._serve(sources)

    def _serve(self, sources: list[Any]) -> None:
        vehicle, _ = self._attached()
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
            vehicle.mission.tick(now)
            self._advance(now)
            self._idle_heartbeat(now)
            self.outbox.expire_peers(now)
            if self.exit_with_parent and os.getppid() != self._parent:
                self.stopping = True

    def stop(self, *_: Any) -> None:
        """Ask the loop to finish (signal handler)."""
        self.stopping = True

    def _next_deadline(self, now: float) -> float:
        if self._pending_deadline is not None:
            return min(self._pending_deadline, now + PENDING_POLL_WALL_S)
        return self._attached()[1].next_deadline(now)

    def _on_message(self, message: Any, sender: Address, now: float) -> None:
        vehicle, pacing = self._attached()
        if message.get_srcSystem() == vehicle.identity.system_id:
            return  # our own echo (e.g. through a mirror)
        if self.outbox.heard(sender, now):
            pacing.last_idle_heartbeat = -math.inf  # a new peer hears from us at once
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
        vehicle, pacing = self._attached()
        if self.outbox.has_last_step and abs(time_s - vehicle.sim_time_s) < 1e-9:
            if self._pending_deadline is None:
                self.outbox.resend_last_step(sender)
                self.stats.resent_steps += 1
            return
        if pacing.may_join(time_s):
            if time_s > MAX_JOIN_S:  # SYSTEM_TIME's time_boot_ms (uint32 ms) would overflow
                vehicle.counters.reject("clock tick too far ahead")
                return
            vehicle.join_clock(time_s)  # a vehicle (re)started into a running mission
        if not pacing.request(time_s, now) and time_s > vehicle.sim_time_s:
            vehicle.counters.reject("clock tick too far ahead")

    def _on_timesync(self, message: Any, now: float) -> None:
        """Real time: answer a TIMESYNC request with this vehicle's clock now (not the last
        step's time: the ground station's offset estimate needs the instant of the reply)."""
        if message.tc1 != 0:
            return
        vehicle, pacing = self._attached()
        vehicle.send(mavlink2.MAVLink_timesync_message(pacing.simulated_ns(now), message.ts1))

    def _others_last_step(self) -> dict[str, tuple[Any, Any]] | None:
        """Each other vehicle's true motion over the step just ended (for contact), from the
        truth channel: in lockstep every vehicle's truth of that step is in before the tick
        that starts this one (it left before the vehicle's step marker)."""
        receiver, (vehicle, pacing) = self.truth_receiver, self._attached()
        if receiver is None or vehicle.clock.steps == 0:
            return None
        receiver.drain()
        motions = receiver.motions(pacing.physical_usec(1), pacing.physical_usec())
        return {VehicleIdentity.from_system_id(s).name: m for s, m in motions.items()}

    # -- stepping ---------------------------------------------------------------------------
    def _advance(self, now: float) -> None:
        pacing = self._attached()[1]
        if self._pending_deadline is not None and not self._finish_pending(now):
            return
        if pacing.lone_step(now):
            self.stats.auto_steps += 1
        while pacing.step_due(now):
            if not self._do_step(now):
                return

    def _do_step(self, now: float) -> bool:
        """One step; False if its publication waits for the work UAV's truth."""
        vehicle, pacing = self._attached()
        with self.outbox.stepping():
            vehicle.step(self._others_last_step())
        physical_usec = pacing.physical_usec()
        if self.truth_sender is not None:
            self.truth_sender.publish(vehicle.kinematics.truth, physical_usec)
        receiver = self.truth_receiver
        if receiver is None or vehicle.identity.is_work or not vehicle.sensor_due():
            self._publish_step(None)
            return True
        receiver.drain()
        truth = receiver.exact(physical_usec)
        silent = self._gave_up_at is not None and self._gave_up_at == receiver.newest_usec()
        if truth is None and receiver.may_still_come(physical_usec) and not silent:
            timeout = vehicle.scenario.vehicle.truth_timeout_wall_s
            self._pending_deadline = now + pacing.truth_wait_wall_s(timeout)
            return False
        self._publish_step(truth if truth is not None else receiver.estimate(physical_usec))
        return True

    def _finish_pending(self, now: float) -> bool:
        receiver, pacing = self.truth_receiver, self._attached()[1]
        assert receiver is not None and self._pending_deadline is not None
        physical_usec = pacing.physical_usec()
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

    def _publish_step(self, truth: Any) -> None:
        """Publish the step's telemetry as one batch of datagrams."""
        vehicle = self._attached()[0]
        self.outbox.publish_step(lambda: vehicle.publish(truth))

    def _idle_heartbeat(self, now: float) -> None:
        vehicle, pacing = self._attached()
        if pacing.idle_heartbeat_due(now):
            self.outbox.broadcast(vehicle.heartbeat())
            if self.truth_sender is not None:  # lets the supports know a work UAV exists
                self.truth_sender.publish(vehicle.kinematics.truth, 0)

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
