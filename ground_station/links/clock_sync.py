"""Each vehicle's clock against the ground station's, from TIMESYNC (real time).

In real time every vehicle keeps its own simulated clock (its time since start, as an
autopilot's time since boot) and stamps its measurements with it. The ground station sends
TIMESYNC requests and each vehicle answers at once with its time; of the recent exchanges
the one with the shortest round trip gives the offset (:mod:`mission.link.timesync`). In
lockstep every clock is the ground station's: the offset is zero.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

from mission.link.timesync import exchange_offset

KEEP_EXCHANGES = 16  # recent exchanges the shortest round trip is chosen from


@dataclass(frozen=True)
class Exchange:
    """One TIMESYNC round trip, in simulated nanoseconds."""

    round_trip_ns: int
    offset_ns: float  # vehicle minus ground station


@dataclass
class ClockOffsets:
    """The offset of each vehicle's clock from the ground station's."""

    exchanges: dict[int, deque[Exchange]] = field(default_factory=dict)

    def observe(self, system_id: int, tc1: int, ts1: int, received_ns: int) -> None:
        """A vehicle's answer (``tc1``, ``ts1``) arrived at ``received_ns``."""
        exchange = exchange_offset(tc1, ts1, received_ns)
        if exchange is None:
            return  # not an answer to one of ours, or garbage
        kept = self.exchanges.setdefault(system_id, deque(maxlen=KEEP_EXCHANGES))
        kept.append(Exchange(*exchange))

    def offset_s(self, system_id: int) -> float | None:
        """The vehicle's clock minus the ground station's, in seconds (None: not known yet)."""
        kept = self.exchanges.get(system_id)
        if not kept:
            return None
        best = min(kept, key=lambda exchange: exchange.round_trip_ns)
        return best.offset_ns / 1e9
