"""The simulation-only truth channel: the work UAV's true position, for the supports' cameras.

A real camera sees the real work UAV; a simulated one must be told where it truly is. The work
vehicle sends LOCAL_POSITION_NED of its *true* position (time_boot_ms = simulated time) after
every step over separate UDP sockets to each support vehicle's truth port. The ground station
never listens on these ports, so truth cannot leak into estimation.
"""

from __future__ import annotations

import socket
from collections import OrderedDict

import numpy as np

from mission.link.mavlink_udp import Address, MavlinkCodec, UdpEndpoint
from mission.world.frames import ned_to_enu
from vehicle_sim import telemetry

KEEP_SAMPLES = 64


class TruthSender:
    """Work side: publish the true position after each step."""

    def __init__(self, system_id: int, destinations: list[Address]) -> None:
        self.destinations = list(destinations)
        self.endpoint = UdpEndpoint(MavlinkCodec(system_id, 1))

    def publish(self, truth_enu: np.ndarray, time_boot_ms: int) -> None:
        """Send the truth at ``time_boot_ms`` to every support."""
        if self.destinations:
            message = telemetry.local_position_ned(truth_enu, np.zeros(3), time_boot_ms)
            self.endpoint.send(message, self.destinations)

    def close(self) -> None:
        """Close the socket."""
        self.endpoint.close()


class TruthReceiver:
    """Support side: keep the work UAV's recent true positions by simulated time.

    In lockstep a support waits (briefly) for the truth of a step only while it may still come:
    once it has heard from a work vehicle at all, and while nothing later has arrived (the
    samples come in order; a later one means this one was lost, came before the support
    listened, or was dropped from the samples kept). A support running alone publishes
    not-valid observations.
    """

    def __init__(
        self, port: int, host: str = "127.0.0.1", sock: socket.socket | None = None
    ) -> None:
        self.endpoint = UdpEndpoint(MavlinkCodec(0, 0), (host, port), sock=sock)
        self.samples: OrderedDict[int, np.ndarray] = OrderedDict()
        self.stale_uses = 0

    def fileno(self) -> int:
        """For select()."""
        return self.endpoint.fileno()

    def drain(self) -> None:
        """Read every pending truth sample."""
        for message, _ in self.endpoint.receive():
            if message.get_type() != "LOCAL_POSITION_NED" or message.get_srcSystem() != 1:
                continue
            position = ned_to_enu(np.array([message.x, message.y, message.z], dtype=float))
            if not np.all(np.isfinite(position)):
                continue
            self.samples[int(message.time_boot_ms)] = position
            self.samples.move_to_end(int(message.time_boot_ms))
            while len(self.samples) > KEEP_SAMPLES:
                self.samples.popitem(last=False)

    def may_still_come(self, time_boot_ms: int) -> bool:
        """Whether the truth at this time is worth waiting for: some truth has arrived, none
        of it later than this time."""
        return bool(self.samples) and max(self.samples) < time_boot_ms

    def exact(self, time_boot_ms: int) -> np.ndarray | None:
        """The truth at exactly this simulated time, if it has arrived."""
        return self.samples.get(time_boot_ms)

    def estimate(self, time_boot_ms: int) -> np.ndarray | None:
        """Truth at this time: exact, else interpolated or extrapolated from neighbours."""
        exact = self.exact(time_boot_ms)
        if exact is not None:
            return exact
        if not self.samples:
            return None
        self.stale_uses += 1
        times = sorted(self.samples)
        if len(times) == 1:
            return self.samples[times[0]]
        before = [t for t in times if t <= time_boot_ms]
        t0 = before[-1] if before else times[0]
        later = [t for t in times if t > t0]
        t1 = later[0] if later else t0
        if t1 == t0:
            t0 = times[-2]
            t1 = times[-1]
        p0, p1 = self.samples[t0], self.samples[t1]
        fraction = (time_boot_ms - t0) / (t1 - t0)
        return p0 + (p1 - p0) * float(np.clip(fraction, -2.0, 2.0))

    def close(self) -> None:
        """Close the socket."""
        self.endpoint.close()
