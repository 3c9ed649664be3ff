"""The supports' true GNSS errors of summary.json against hand-made traces, and the threshold
against scipy's chi-square distributions (an independent answer)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import optimize, stats

from mission.analysis.gnss_errors import detectable_bias_m, gnss_error_metrics
from mission.analysis.trace import RunTrace


def test_the_threshold_is_the_motion_tests_best_direction_mdb(along_world):
    scenario = along_world.scenario
    gate = stats.chi2.isf(scenario.integrity.false_alarm, 3)
    lam = optimize.brentq(
        lambda x: stats.ncx2.cdf(gate, 3, x) - scenario.integrity.missed_detection, 1e-3, 500
    )
    geometry = along_world.gnss.geometry_from_visibility(along_world.sky.above_mask[None].copy())
    covariance = 2 * 0.1**2 * geometry.cov_geom[0] + 0.05**2 * np.eye(3)
    expected = np.sqrt(lam * np.linalg.eigvalsh(covariance)[0])
    assert detectable_bias_m(along_world) == pytest.approx(expected, rel=1e-3)
    assert 0.5 < expected < 1.0  # docs/ground-station.md's 0.9-1.9 m is S's whole range


def test_errors_and_steps_over_the_threshold_per_support(along_world):
    trace = RunTrace()
    threshold = detectable_bias_m(along_world)
    offsets = {2: [0.1, 0.2, 2.0, 3.0], 3: [0.0, 0.0, 0.0, threshold + 0.01]}
    for system, errors in offsets.items():
        for step, error in enumerate(errors):
            t = 0.5 * step
            trace.truth[(system, t)] = np.array([1.0, 2.0, 3.0])
            trace.fixes[(system, t)] = np.array([1.0, 2.0, 3.0 + error])
    trace.fixes[(2, 9.0)] = np.zeros(3)  # no truth near it: not counted
    metrics = gnss_error_metrics(trace, along_world)
    assert metrics["gnss_error_steps"] == {"support-1": 2, "support-2": 1}
    assert metrics["gnss_error_steps_total"] == 3
    assert metrics["support_gnss_error_m"]["support-1"]["max"] == pytest.approx(3.0)
    assert metrics["support_gnss_error_m"]["support-1"]["mean"] == pytest.approx(1.325)
