"""Step 3 of the control cycle: the paper's arrival check on the work UAV's estimate."""

from __future__ import annotations

import numpy as np

from ground_station.state.station_state import StationState


def check_arrival(state: StationState, waypoints: np.ndarray, tolerance_m: float) -> int | None:
    """Advance k when |w_k - xhat| < tolerance (the task is complete at the last waypoint);
    return the index reached, if any."""
    if np.linalg.norm(waypoints[state.k] - state.xhat) >= tolerance_m:
        return None
    reached = state.k
    if state.k == len(waypoints) - 1:
        state.completed = True
    else:
        state.k += 1
    return reached
