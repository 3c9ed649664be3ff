"""The tracking error of a hand-built trace against the answers worked out by hand."""

from __future__ import annotations

import numpy as np
import pytest

from mission.analysis.metrics import RunTrace
from mission.analysis.tracking import tracking_errors, tracking_metrics


def _trace() -> RunTrace:
    """Vehicle 1 over three 0.5 s cycles at 1 m/s (reach 0.5 m a cycle):
    - t 0: estimate (0,0,0), setpoint (2,0,0) far: the ideal ends at (0.5,0,0); the vehicle
      believes (0.4,0,0) at t 0.5: error 0.1;
    - t 0.5: blind (no estimate): it steers from its belief (0.4,0,0) toward (0.4,0.3,0),
      within reach: the ideal ends there; it believes (0.4,0.3,0.4) at t 1.0: error 0.4;
    - t 1.0: estimate (1,1,1), setpoint (1,1,1): hold; it believes (1,1,1) at t 1.5: 0.
    The last setpoint (t 1.5) ends no cycle. Vehicle 2 has one setpoint: no cycle."""
    trace = RunTrace(max_gap_s=1.0)
    beliefs = {0.0: (0, 0, 0), 0.5: (0.4, 0, 0), 1.0: (0.4, 0.3, 0.4), 1.5: (1, 1, 1)}
    for t, belief in beliefs.items():
        trace.beliefs[(1, t)] = np.array(belief, dtype=float)
    setpoints = {0.0: (2, 0, 0), 0.5: (0.4, 0.3, 0), 1.0: (1, 1, 1), 1.5: (5, 5, 5)}
    for t, setpoint in setpoints.items():
        trace.setpoints[(1, t)] = np.array(setpoint, dtype=float)
    trace.sent_estimates[(1, 0.0)] = np.zeros(3)
    trace.sent_estimates[(1, 1.0)] = np.ones(3)
    trace.setpoints[(2, 0.0)] = np.zeros(3)
    trace.truth[(2, 0.0)] = np.zeros(3)  # makes system 2 a support
    return trace


def test_each_cycle_is_measured_against_the_ideal_point_from_where_it_steered():
    errors = tracking_errors(_trace(), speed_m_s=1.0, system=1)
    np.testing.assert_allclose(errors, [0.1, 0.4, 0.0], atol=1e-12)


def test_a_cycle_whose_end_is_not_known_is_left_out():
    trace = _trace()
    del trace.beliefs[(1, 1.0)]  # interpolated between 0.5 and 1.5 instead: gap 1.0 allowed
    assert len(tracking_errors(trace, 1.0, 1)) == 3
    trace.max_gap_s = 0.5  # unknown now: the cycle from 0.5 ends unknown; the one from 1.0
    # starts from its estimate and is still measured
    np.testing.assert_allclose(tracking_errors(trace, 1.0, 1), [0.1, 0.0], atol=1e-12)


def test_the_metrics_report_the_work_uav_and_the_supports_apart():
    metrics = tracking_metrics(_trace(), work_speed_m_s=1.0, support_speed_m_s=1.0)
    assert metrics["work"] == {
        "mean": pytest.approx(round(0.5 / 3, 4)),
        "p95": pytest.approx(round(0.1 + 0.9 * 0.3, 4)),  # numpy's linear percentile
        "max": 0.4,
    }
    assert metrics["supports"] == {"mean": None, "p95": None, "max": None}
