"""The ground station's links to its vehicles: one UDP endpoint, a view of each vehicle, and
every packet in and out written to the tlog at the clock's simulated time.

Messages are accepted only from the vehicles' own addresses. SIM_STATE (the simulator's truth)
goes to the tlog for analysis and is not kept: nothing here or above can read it.

A measurement's time is its own stamp (``time_usec``), mapped onto the ground station's clock
with the vehicle's clock offset (:mod:`~ground_station.links.clock_sync`); its age at a cycle is
the cycle's time minus that. In lockstep only the step's own measurements are used: age zero.
"""

from __future__ import annotations

import socket
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from ground_station.links.clock import StationClock
from ground_station.links.clock_sync import ClockOffsets
from ground_station.links.outgoing import (
    GCS_COMPONENT_ID,
    GCS_SYSTEM_ID,
    GUIDED_AND_ARMED,
    command_long,
    timesync_request,
)
from ground_station.links.tlog import TlogWriter
from mission.link.impairment import LinkSettings
from mission.link.mavlink_udp import Address, MavlinkCodec, MessageQueue, UdpEndpoint
from mission.link.statustext import statustexts
from mission.link.vehicle_identity import VehicleIdentity

TRUTH_KINDS = frozenset({"SIM_STATE"})  # logged, never kept
MAX_AGE_STEPS = 2.0  # real time: a measurement older than this many cycles is not used


@dataclass(frozen=True)
class SupportSample:
    """A support's latest GNSS fix and camera observation for a cycle, with their ages in
    simulated seconds at the cycle's time (None where missing or too old)."""

    name: str
    gps: Any | None
    target: Any | None
    gps_age_s: float = 0.0
    target_age_s: float = 0.0
    belief: Any | None = None  # LOCAL_POSITION_NED of the cycle's own step (lockstep), if any


class StationError(RuntimeError):
    """The run cannot go on (a vehicle never appeared, refused its mission, fell silent...)."""


@dataclass
class VehicleView:
    """What the ground station holds about one vehicle."""

    name: str
    system_id: int
    address: Address
    latest: dict[str, Any] = field(default_factory=dict)  # the last message of each kind
    step_ms: int = -1
    heartbeat_wall: float = -1.0
    heard_s: float = 0.0  # simulated time of the last message from it
    lost: bool = False  # silent for link_loss_s: out of fusion and the MPCs
    late: bool = False  # missed the last lockstep marker: not waited for
    outbox: list[tuple[Any, bytes]] = field(default_factory=list)  # (message, packet) unsent
    last_batch: list[Any] = field(default_factory=list)  # the messages last sent together
    crash: str | None = None  # the vehicle's own word that it crashed (its STATUSTEXT)


class VehicleLinks:
    """Sends, receives and logs for every vehicle; knows who is heard and who is lost."""

    def __init__(
        self,
        vehicles: dict[str, Address],
        clock: StationClock,
        tlog: TlogWriter,
        signing_key: bytes | None,
        link: LinkSettings,
        seed: int,
    ) -> None:
        self.clock = clock
        self.tlog = tlog
        self._statustext_id = 0  # the last id of a STATUSTEXT sent in chunks
        self.endpoint = UdpEndpoint(
            MavlinkCodec(GCS_SYSTEM_ID, GCS_COMPONENT_ID, signing_key),
            link=link,
            link_seed=seed * 1000 + GCS_SYSTEM_ID,
        )
        self.queue = MessageQueue(self.endpoint)
        self.views = {
            name: VehicleView(name, VehicleIdentity.parse(name).system_id, _resolved(address))
            for name, address in vehicles.items()
        }
        self.by_system = {v.system_id: v for v in self.views.values()}
        self.stats = {"lost_in": 0, "tick_resends": 0, "late_steps": 0}
        self.offsets = ClockOffsets()
        self._last_seq: dict[int, int] = {}

    # -- out --------------------------------------------------------------------------------
    def send(self, message: Any, view: VehicleView) -> None:
        """Send to one vehicle now and log the packet."""
        self.tlog.write(self.clock.time_usec, self.endpoint.send(message, [view.address]))

    def queue_for(self, message: Any, view: VehicleView) -> None:
        """Log the packet now (its time and sequence number are now's) and send it with the
        vehicle's other packets of the cycle at :meth:`flush`."""
        packet = self.endpoint.encode(message)
        self.tlog.write(self.clock.time_usec, packet)
        view.outbox.append((message, packet))

    def flush(self, view: VehicleView) -> None:
        """The vehicle's queued packets out, in order, in one datagram (commands and tick
        wake a vehicle once, not three times)."""
        if view.outbox:
            self.endpoint.send_packets([packet for _, packet in view.outbox], [view.address])
            view.last_batch = [message for message, _ in view.outbox]
            view.outbox = []

    def flush_all(self) -> None:
        """Every vehicle's queued packets out."""
        for view in self.views.values():
            self.flush(view)

    def resend_last_batch(self, view: VehicleView) -> None:
        """Queue the vehicle's last datagram again, encoded afresh (a signed link refuses a
        replayed packet)."""
        for message in view.last_batch:
            self.queue_for(message, view)
        self.stats["tick_resends"] += 1

    def command_long(self, view: VehicleView, command: int, params: tuple[float, ...]) -> None:
        """Send a COMMAND_LONG now."""
        self.send(command_long(view.system_id, command, params), view)

    def sync_clocks(self) -> None:
        """Real time: a TIMESYNC request to every vehicle, stamped with the time it leaves."""
        for view in self.views.values():
            self.send(timesync_request(round(self.clock.now_s() * 1e9)), view)

    def announce(self, text: str, to_stderr: bool = False) -> None:
        """A STATUSTEXT in the tlog (and on stderr for link events)."""
        if to_stderr:
            print(
                f"ground station: t={self.clock.time_s:.1f} s: {text}", file=sys.stderr, flush=True
            )
        self._statustext_id = self._statustext_id % 65535 + 1
        for message in statustexts(text, self._statustext_id):
            self.tlog.write(self.clock.time_usec, self.endpoint.send(message, []))

    # -- in ---------------------------------------------------------------------------------
    def receive(self, message: Any, sender: Address) -> None:
        """Log a message from a vehicle and note what it says about the vehicle."""
        view = self.by_system.get(message.get_srcSystem())
        if view is None or sender != view.address:  # only our vehicles, from where they are
            self.endpoint.counters.reject("unknown sender")
            return
        self.tlog.write(self.clock.now_usec(), message.get_msgbuf())
        self._count_gap(view.system_id, message.get_seq())
        kind = message.get_type()
        if kind == "TIMESYNC" and not self.clock.lockstep:
            received_ns = round(self.clock.now_s() * 1e9)
            self.offsets.observe(view.system_id, message.tc1, message.ts1, received_ns)
        if kind not in TRUTH_KINDS:
            view.latest[kind] = message
        view.heard_s = self.clock.time_s
        if kind == "STATUSTEXT" and message.text.startswith("Crash:") and view.crash is None:
            view.crash = message.text
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
                self.stats["lost_in"] += gap
            else:
                return
        self._last_seq[system_id] = seq

    def reset_loss_count(self) -> None:
        """Count losses from here on (set-up traffic is not all logged here)."""
        self._last_seq.clear()
        self.stats["lost_in"] = 0

    def pump(self, seconds: float, until: Callable[[], bool] | None = None) -> None:
        """Receive and log for up to ``seconds`` or until ``until()`` holds."""
        deadline = time.monotonic() + seconds
        while until is None or not until():
            got = self.queue.next(deadline - time.monotonic())
            if got is None:
                return
            self.receive(*got)

    def current(self, name: str, kind: str) -> Any | None:
        """The vehicle's message of this kind from the current step (None if late or
        missing; in real time, the latest)."""
        message = self.views[name].latest.get(kind)
        if message is None:
            return None
        if self.clock.lockstep and abs(int(message.time_usec) - self.clock.time_usec) > 1000:
            return None
        return message

    def age_s(self, name: str, message: Any | None) -> float | None:
        """The age of a measurement at the current cycle (None: missing, too old, or its
        vehicle's clock not known yet)."""
        if message is None:
            return None
        if self.clock.lockstep:
            return 0.0
        offset = self.offsets.offset_s(self.views[name].system_id)
        if offset is None:
            return None
        age = self.clock.time_s - self.clock.sample_time_s(int(message.time_usec), offset)
        return age if age <= MAX_AGE_STEPS * self.clock.step_s else None

    def support_samples(self) -> list[SupportSample]:
        """Each support's GPS_RAW_INT and LANDING_TARGET for this cycle with their ages, and
        its autopilot's belief (LOCAL_POSITION_NED) where it is of this cycle's own step, for
        every support not lost."""
        samples = []
        for name, view in self.views.items():
            if name == "work" or view.lost:
                continue
            gps, target = self.current(name, "GPS_RAW_INT"), self.current(name, "LANDING_TARGET")
            gps_age, target_age = self.age_s(name, gps), self.age_s(name, target)
            belief = self._belief_of_this_step(name)
            samples.append(
                SupportSample(
                    name,
                    gps if gps_age is not None else None,
                    target if target_age is not None else None,
                    gps_age or 0.0,
                    target_age or 0.0,
                    belief,
                )
            )
        return samples

    def _belief_of_this_step(self, name: str) -> Any | None:
        """The vehicle's LOCAL_POSITION_NED of this very step (lockstep only: its boot time is
        the run's simulated time; in real time, None)."""
        belief = self.views[name].latest.get("LOCAL_POSITION_NED")
        if not self.clock.lockstep or belief is None:
            return None
        return belief if int(belief.time_boot_ms) == round(self.clock.time_s * 1000) else None

    # -- who is there -----------------------------------------------------------------------
    def supervise(self, link_loss_s: float, rejoin_within_s: float) -> list[str]:
        """Drop a support silent for ``link_loss_s`` from fusion and the MPCs (a silent work
        UAV ends the run); take one back, GUIDED and armed again, once heard within
        ``rejoin_within_s``. Returns the supports taken back."""
        back = []
        for view in self.views.values():
            silent = self.clock.time_s - view.heard_s
            if not view.lost and silent >= link_loss_s - 1e-9:
                if view.name == "work":
                    raise StationError(f"work lost: no message for {silent:.1f} s")
                view.lost = True
                self.announce(f"{view.name} lost: silent {silent:.1f} s", to_stderr=True)
            elif view.lost and silent < rejoin_within_s - 1e-9:
                view.lost = False
                for command, params in GUIDED_AND_ARMED:  # its ACKs come with later steps
                    self.command_long(view, command, params)
                self.announce(f"{view.name} back", to_stderr=True)
                back.append(view.name)
        return back

    def report(self, settings: LinkSettings) -> dict[str, Any]:
        """What the links lost and how the lockstep recovered (``link.json``)."""
        link = self.endpoint.link
        return {
            "loss": settings.loss,
            "delay_ms": settings.delay_ms,
            "sent_out": link.attempted if link is not None else None,
            "dropped_out": link.dropped if link is not None else 0,
            **self.stats,
            "rejected": dict(self.endpoint.counters.rejected),
        }

    def close(self) -> None:
        """Close the socket."""
        self.endpoint.close()


def _resolved(address: Address) -> Address:
    """(IP, port): replies come from an IP address, so names are looked up once here."""
    host, port = address
    try:
        return socket.gethostbyname(host), port
    except OSError:
        raise StationError(f"cannot resolve vehicle host {host!r}") from None
