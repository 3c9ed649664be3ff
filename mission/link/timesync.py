"""TIMESYNC, the MAVLink clock exchange: a request carries the asker's time (``ts1``, tc1 = 0);
the answer echoes it with the answerer's time (``tc1``). NTP's estimate of the answerer's
clock minus the asker's from one exchange is ``tc1 - (ts1 + tr)/2`` (``tr``: the answer's
arrival), off by at most half the round trip, so the exchange with the shortest round trip
is the one to trust. Used live by the ground station and afterwards by the tlog analysis.
"""

from __future__ import annotations


def exchange_offset(tc1_ns: int, ts1_ns: int, received_ns: int) -> tuple[int, float] | None:
    """(round trip, answerer minus asker) in nanoseconds of one exchange; None if it is not
    an answer (tc1 0) or arrived before it left (garbage)."""
    round_trip = received_ns - ts1_ns
    if tc1_ns <= 0 or round_trip < 0:
        return None
    return round_trip, tc1_ns - (ts1_ns + received_ns) / 2
