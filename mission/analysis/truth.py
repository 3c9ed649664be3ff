"""The simulator's truth in a ground station's tlog, on the ground station's clock.

Each vehicle sends SIM_STATE (its true position) in a step's telemetry, followed by that step's
SYSTEM_TIME marker, whose stamp is the step's time on the vehicle's own clock: the truth's
time. In lockstep every clock is the ground station's. In real time each vehicle's clock is
its own; the TIMESYNC exchanges in the tlog give its offset as they gave it to the ground
station (the exchange with the shortest round trip, :mod:`mission.link.timesync`). Between
samples the truth is interpolated linearly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mission.link.timesync import exchange_offset

TIME_DECIMALS = 4  # truth times are kept to 0.1 ms (lockstep's fall on whole milliseconds)


@dataclass(frozen=True)
class TimesyncReply:
    """A vehicle's answer to a TIMESYNC request, as logged: its clock ``tc1``, the request's
    stamp ``ts1`` and the reply's arrival on the ground station's clock (all nanoseconds)."""

    system: int
    tc1_ns: int
    ts1_ns: int
    received_ns: int


def clock_offsets(replies: list[TimesyncReply]) -> dict[int, float]:
    """Each vehicle's clock minus the ground station's (seconds), from its exchange with the
    shortest round trip; vehicles with no exchange are not in the result."""
    best: dict[int, tuple[int, float]] = {}
    for reply in replies:
        exchange = exchange_offset(reply.tc1_ns, reply.ts1_ns, reply.received_ns)
        if exchange is not None and exchange[0] < best.get(reply.system, (float("inf"),))[0]:
            best[reply.system] = exchange
    return {system: offset / 1e9 for system, (_, offset) in best.items()}


def truth_time(stamp_usec: int, epoch_usec: int, offset_s: float) -> float:
    """A vehicle's stamp (UNIX microseconds of its clock) as seconds of the ground station's
    clock from the scenario's epoch."""
    return round((stamp_usec - epoch_usec) / 1e6 - offset_s, TIME_DECIMALS)


def interpolate(
    times: np.ndarray, positions: np.ndarray, at: np.ndarray, max_gap_s: float
) -> tuple[np.ndarray, np.ndarray]:
    """Positions at the times ``at`` (linear between the samples around each), and which of
    them are known: a time that is a sample's, or lies between two samples at most
    ``max_gap_s`` apart."""
    at = np.asarray(at, dtype=float)
    if len(times) == 0:
        return np.full((len(at), 3), np.nan), np.zeros(len(at), dtype=bool)
    after = np.searchsorted(times, at, side="left")
    exact = (after < len(times)) & (times[np.minimum(after, len(times) - 1)] == at)
    inside = (after > 0) & (after < len(times))
    gap = np.where(
        inside, times[np.minimum(after, len(times) - 1)] - times[np.maximum(after - 1, 0)], np.inf
    )
    known = exact | (inside & (gap <= max_gap_s + 1e-9))
    result = np.column_stack([np.interp(at, times, positions[:, axis]) for axis in range(3)])
    if exact.any():  # a sample's own time gives the sample itself, bit for bit
        result[exact] = positions[after[exact]]
    result[~known] = np.nan
    return result, known
