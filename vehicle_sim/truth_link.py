"""The simulation-only truth channel: the work UAV's true position, for the supports' cameras.

A real camera sees the real work UAV; a simulated one must be told where it truly is. After
every step the work vehicle sends ATT_POS_MOCAP (a motion-capture fix: the truth) of its true
position over separate UDP sockets to each support vehicle's truth port. The ground station
never listens on these ports, so truth cannot leak into estimation.

Each sample carries the physical time of the step it ends (``time_usec``): the simulated time
in lockstep, where every vehicle shares the ground station's clock; the host's wall clock
(UNIX microseconds) in real time, where each vehicle keeps its own simulated clock but all
move through the same physical time. A support looks the truth up at its own sample's
physical time: exactly, else interpolated between the samples around it.
"""

from __future__ import annotations

import socket
from collections import OrderedDict

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.link.mavlink_udp import Address, MavlinkCodec, UdpEndpoint
from mission.world.frames import enu_to_ned, ned_to_enu

KEEP_SAMPLES = 64
UNIT_QUATERNION = [1.0, 0.0, 0.0, 0.0]


def truth_message(truth_enu: np.ndarray, time_usec: int) -> mavlink2.MAVLink_att_pos_mocap_message:
    """ATT_POS_MOCAP of a true position (NED) at physical time ``time_usec``."""
    north, east, down = (float(v) for v in enu_to_ned(truth_enu))
    return mavlink2.MAVLink_att_pos_mocap_message(
        time_usec, UNIT_QUATERNION, north, east, down, [0.0] * 21
    )


class TruthSender:
    """Work side: publish the true position after each step."""

    def __init__(self, system_id: int, destinations: list[Address]) -> None:
        self.destinations = list(destinations)
        self.endpoint = UdpEndpoint(MavlinkCodec(system_id, 1))

    def publish(self, truth_enu: np.ndarray, time_usec: int) -> None:
        """Send the truth at physical time ``time_usec`` to every support."""
        if self.destinations:
            self.endpoint.send(truth_message(truth_enu, time_usec), self.destinations)

    def close(self) -> None:
        """Close the socket."""
        self.endpoint.close()


class TruthReceiver:
    """Support side: keep the work UAV's recent true positions by physical time.

    A support waits (briefly) for the truth of its sample only while it may still come: once
    it has heard from a work vehicle at all, and while nothing at or after that time has
    arrived (the samples come in order). A support running alone publishes not-valid
    observations.
    """

    def __init__(
        self, port: int, host: str = "127.0.0.1", sock: socket.socket | None = None
    ) -> None:
        self.endpoint = UdpEndpoint(MavlinkCodec(0, 0), (host, port), sock=sock)
        self.samples: OrderedDict[int, np.ndarray] = OrderedDict()
        self.extrapolated = 0  # samples looked up beyond the newest truth
        self.interpolated = 0  # samples looked up between two truths

    def fileno(self) -> int:
        """For select()."""
        return self.endpoint.fileno()

    def drain(self) -> None:
        """Read every pending truth sample."""
        for message, _ in self.endpoint.receive():
            if message.get_type() != "ATT_POS_MOCAP" or message.get_srcSystem() != 1:
                continue
            position = ned_to_enu(np.array([message.x, message.y, message.z], dtype=float))
            if not np.all(np.isfinite(position)):
                continue
            time_usec = int(message.time_usec)
            self.samples[time_usec] = position
            self.samples.move_to_end(time_usec)
            while len(self.samples) > KEEP_SAMPLES:
                self.samples.popitem(last=False)

    def may_still_come(self, time_usec: int) -> bool:
        """Whether the truth at this time is worth waiting for: some truth has arrived, none
        of it at or after this time."""
        return bool(self.samples) and max(self.samples) < time_usec

    def exact(self, time_usec: int) -> np.ndarray | None:
        """The truth at exactly this time, if it has arrived."""
        return self.samples.get(time_usec)

    def estimate(self, time_usec: int) -> np.ndarray | None:
        """Truth at this time: exact, else interpolated between the samples around it, else
        extrapolated from the two nearest (clipped: one interval past the newest,
        two before the oldest)."""
        exact = self.exact(time_usec)
        if exact is not None:
            return exact
        if not self.samples:
            return None
        times = sorted(self.samples)
        if len(times) == 1:
            self.extrapolated += 1
            return self.samples[times[0]]
        after = int(np.searchsorted(times, time_usec))
        if 0 < after < len(times):
            self.interpolated += 1
            t0, t1 = times[after - 1], times[after]
        else:
            self.extrapolated += 1
            t0, t1 = (times[0], times[1]) if after == 0 else (times[-2], times[-1])
        p0, p1 = self.samples[t0], self.samples[t1]
        fraction = (time_usec - t0) / (t1 - t0)
        return p0 + (p1 - p0) * float(np.clip(fraction, -2.0, 2.0))

    def close(self) -> None:
        """Close the socket."""
        self.endpoint.close()
