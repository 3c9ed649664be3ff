"""The simulation-only truth channel: every vehicle's true position, for the supports' cameras
and for contact between vehicles.

A real camera sees the real work UAV, and real vehicles touch; simulated ones must be told where
the others truly are. After every step each vehicle sends ATT_POS_MOCAP (a motion-capture fix:
the truth) of its true position over separate UDP sockets to every other vehicle's truth port.
The ground station never listens on these ports, so truth cannot leak into estimation.

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
    """Publish this vehicle's true position after each step to the other vehicles."""

    def __init__(self, system_id: int, destinations: list[Address]) -> None:
        self.destinations = list(destinations)
        self.endpoint = UdpEndpoint(MavlinkCodec(system_id, 1))

    def publish(self, truth_enu: np.ndarray, time_usec: int) -> None:
        """Send the truth at physical time ``time_usec`` to every other vehicle."""
        if self.destinations:
            self.endpoint.send(truth_message(truth_enu, time_usec), self.destinations)

    def close(self) -> None:
        """Close the socket."""
        self.endpoint.close()


class TruthReceiver:
    """Keep the other vehicles' recent true positions by physical time, per system id (the
    work UAV is system 1).

    A support waits (briefly) for the work UAV's truth of its camera sample only while it may
    still come: once it has heard from a work vehicle at all, and while nothing at or after
    that time has arrived (the samples come in order). A support running alone publishes
    not-valid observations.
    """

    def __init__(
        self,
        port: int,
        host: str = "127.0.0.1",
        sock: socket.socket | None = None,
        own_system: int = 0,
    ) -> None:
        self.endpoint = UdpEndpoint(MavlinkCodec(0, 0), (host, port), sock=sock)
        self.own_system = own_system
        self.by_system: dict[int, OrderedDict[int, np.ndarray]] = {}
        self.extrapolated = 0  # samples looked up beyond the newest truth
        self.interpolated = 0  # samples looked up between two truths

    def fileno(self) -> int:
        """For select()."""
        return self.endpoint.fileno()

    def drain(self) -> None:
        """Read every pending truth sample."""
        for message, _ in self.endpoint.receive():
            system = message.get_srcSystem()
            if message.get_type() != "ATT_POS_MOCAP" or system == self.own_system:
                continue
            position = ned_to_enu(np.array([message.x, message.y, message.z], dtype=float))
            if not np.all(np.isfinite(position)):
                continue
            time_usec = int(message.time_usec)
            samples = self.by_system.setdefault(system, OrderedDict())
            samples[time_usec] = position
            samples.move_to_end(time_usec)
            while len(samples) > KEEP_SAMPLES:
                samples.popitem(last=False)

    @property
    def samples(self) -> OrderedDict[int, np.ndarray]:
        """The work UAV's samples (the camera's)."""
        return self.by_system.get(1, OrderedDict())

    def motions(self, start_usec: int, end_usec: int) -> dict[int, tuple[np.ndarray, np.ndarray]]:
        """Each other vehicle's true positions at the start and the end of a step, for those
        heard from at or after its start (exact, else interpolated or extrapolated)."""
        found = {}
        for system, samples in self.by_system.items():
            if samples and next(reversed(samples)) >= start_usec:
                start = self._estimate(samples, start_usec, count=False)
                end = self._estimate(samples, end_usec, count=False)
                if start is not None and end is not None:
                    found[system] = (start, end)
        return found

    def may_still_come(self, time_usec: int) -> bool:
        """Whether the truth at this time is worth waiting for: some truth has arrived, none
        of it at or after this time."""
        return bool(self.samples) and max(self.samples) < time_usec

    def newest_usec(self) -> int | None:
        """The time of the newest truth sample (None before any)."""
        return max(self.samples) if self.samples else None

    def exact(self, time_usec: int) -> np.ndarray | None:
        """The truth at exactly this time, if it has arrived."""
        return self.samples.get(time_usec)

    def estimate(self, time_usec: int) -> np.ndarray | None:
        """Truth at this time: exact, else interpolated between the samples around it, else
        extrapolated from the two nearest (clipped: one interval past the newest,
        two before the oldest)."""
        return self._estimate(self.samples, time_usec, count=True)

    def _estimate(
        self, samples: OrderedDict[int, np.ndarray], time_usec: int, count: bool
    ) -> np.ndarray | None:
        exact = samples.get(time_usec)
        if exact is not None:
            return exact
        if not samples:
            return None
        times = sorted(samples)
        if len(times) == 1:
            self.extrapolated += count
            return samples[times[0]]
        after = int(np.searchsorted(times, time_usec))
        if 0 < after < len(times):
            self.interpolated += count
            t0, t1 = times[after - 1], times[after]
        else:
            self.extrapolated += count
            t0, t1 = (times[0], times[1]) if after == 0 else (times[-2], times[-1])
        p0, p1 = samples[t0], samples[t1]
        fraction = (time_usec - t0) / (t1 - t0)
        return p0 + (p1 - p0) * float(np.clip(fraction, -2.0, 2.0))

    def close(self) -> None:
        """Close the socket."""
        self.endpoint.close()
