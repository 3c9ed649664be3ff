"""How well each vehicle's autopilot tracks the ground station's setpoints, from the tlog.

A vehicle is sent a position setpoint (SET_POSITION_TARGET_LOCAL_NED) each control cycle,
after the estimate that resets what it believes (VISION_POSITION_ESTIMATE; a blind work UAV
gets none and goes on with its own belief). Over the cycle an ideal vehicle - the kinematic
point of :mod:`vehicle_sim.dynamics.kinematics` - would move from its belief toward the
setpoint by at most its speed limit times the cycle; toward a setpoint with a velocity (a
flying vehicle's feed-forward), as far as the setpoint moves at that velocity. The
**tracking error** of a cycle is the distance between where the vehicle then believes it is
(LOCAL_POSITION_NED at the next cycle's time, before that cycle's estimate) and where the
ideal vehicle would be. It is measured in the frame the autopilot steers in (its belief), so
it is the control loop's lag and overshoot, not the estimate's error (the work UAV's error is
``work_error_m``); a kinematic point without tracking noise scores 0 up to the messages'
float32 rounding.

Exact in lockstep (every belief sample falls on a cycle's time); in real time the beliefs
are interpolated to the cycles' times, which can mix in an estimate's jump.
"""

from __future__ import annotations

import numpy as np

from mission.analysis.spread import spread
from mission.analysis.trace import RunTrace
from mission.analysis.truth import interpolate

WORK_SYSTEM = 1


def tracking_errors(trace: RunTrace, speed_m_s: float, system: int) -> np.ndarray:
    """The tracking error (m) of each cycle of ``system`` whose start and end beliefs are
    known; its speed limit ``speed_m_s``."""
    times = np.array(sorted(t for s, t in trace.setpoints if s == system))
    if len(times) < 2:
        return np.zeros(0)
    belief_times = np.array(sorted(t for s, t in trace.beliefs if s == system))
    beliefs = np.array([trace.beliefs[(system, t)] for t in belief_times]).reshape(-1, 3)
    held, known = interpolate(belief_times, beliefs, times, trace.max_gap_s)
    errors = []
    for k in range(len(times) - 1):
        start_time, end_time = float(times[k]), float(times[k + 1])
        start = trace.sent_estimates.get((system, start_time))
        if start is None:  # no estimate this cycle: it steered from its own belief
            start = held[k] if known[k] else None
        if start is None or not known[k + 1]:
            continue
        key = (system, start_time)
        velocity = trace.setpoint_velocities.get(key)
        wanted = trace.setpoints[key] - start
        if velocity is not None:
            wanted = wanted + velocity * (end_time - start_time)
        distance = float(np.linalg.norm(wanted))
        reach = speed_m_s * (end_time - start_time)
        ideal = start + (wanted if distance <= reach else wanted * (reach / distance))
        errors.append(float(np.linalg.norm(held[k + 1] - ideal)))
    return np.array(errors)


def tracking_metrics(trace: RunTrace, work_speed_m_s: float, support_speed_m_s: float) -> dict:
    """Mean, p95 and max tracking error of the work UAV and of all the supports together."""
    work = tracking_errors(trace, work_speed_m_s, WORK_SYSTEM)
    supports = [tracking_errors(trace, support_speed_m_s, s) for s in trace.supports]
    return {
        "work": spread([float(e) for e in work]),
        "supports": spread([float(e) for s in supports for e in s]),
    }
