"""Real time on a common beat: the instants at which the host's wall clock (UNIX time, kept by
NTP or a GNSS receiver on real hardware) is a whole number of steps since the epoch.

Vehicles that start their real-time clocks on this grid sample at the same physical instants,
as sensors triggered by a GNSS receiver's pulse per second do; their simulated clocks still
differ (each counts from its own start). The ground station runs its cycles a fixed fraction
of a step after the grid, when the step's measurements have arrived.
"""

from __future__ import annotations

import math
import time


def next_grid_instant(step_wall_s: float, lag_s: float = 0.0) -> tuple[float, float]:
    """(time.monotonic(), time.time()) of the next instant ``lag_s`` after a multiple of
    ``step_wall_s`` of UNIX time."""
    now_unix, now_monotonic = time.time(), time.monotonic()
    grid_unix = math.ceil((now_unix - lag_s) / step_wall_s) * step_wall_s + lag_s
    return now_monotonic + (grid_unix - now_unix), grid_unix
