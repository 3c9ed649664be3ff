"""The supports' true GNSS errors in a run, from the tlog: every 3-D fix a support
reported against its truth at that step.

- ``gnss_multipath``: where the errors came from (the scenario's ``world.gnss.multipath``);
- ``support_gnss_error_m``: per support, mean, p95 and max of |fix - truth|;
  ``supports_gnss_error_m`` the same over all supports' fixes;
- ``gnss_error_steps``: per support, the fixes whose error exceeds ``detectable_bias_m``, the
  integrity monitor's motion test's minimal detectable bias in its best direction in the open
  sky (lambda* of the settings' false-alarm and missed-detection rates, on the test's
  covariance there: the fix's and the last estimate's Sigma_GNSS and the motion's spread).
  A bias this large is one a monitor can be sure to catch; where the multipath comes from
  zones, it counts the steps whose fix a zone moved that far.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mission.analysis.spread import spread
from mission.analysis.trace import RunTrace
from mission.maths.chi_square import detectable_noncentrality
from mission.world.model import World


def detectable_bias_m(world: World) -> float:
    """The motion test's minimal detectable bias in its best direction, open sky."""
    scenario = world.scenario
    integrity = scenario.integrity
    open_sky = world.gnss.geometry_from_visibility(world.sky.above_mask[None].copy())
    sigma_gnss = scenario.gnss.sigma_uere_m**2 * open_sky.cov_geom[0]
    motion = (
        integrity.motion_sigma_multicopter_m
        if scenario.vehicle.dynamics == "multicopter"
        else integrity.motion_sigma_m
    )
    covariance = 2 * sigma_gnss + motion**2 * np.eye(3)
    detectable = detectable_noncentrality(integrity.false_alarm, integrity.missed_detection)
    return float(np.sqrt(detectable * np.linalg.eigvalsh(covariance)[0]))


def fixes_and_truth(trace: RunTrace, system: int) -> tuple[np.ndarray, np.ndarray]:
    """(fixes, truth there) of one vehicle's 3-D fixes whose truth is known, each (n, 3)."""
    times = sorted(t for s, t in trace.fixes if s == system)
    truth, known = trace.truth_at(system, times)
    fixes = np.array([trace.fixes[(system, t)] for t in times]).reshape(-1, 3)
    return fixes[known], truth[known]


def support_fix_errors(trace: RunTrace) -> dict[int, np.ndarray]:
    """Per support system id, |fix - truth| of each 3-D fix whose truth is known."""
    errors = {}
    for system in trace.supports:
        fixes, truth = fixes_and_truth(trace, system)
        errors[system] = np.linalg.norm(fixes - truth, axis=1)
    return errors


def gnss_error_metrics(trace: RunTrace, world: World) -> dict[str, Any]:
    """summary.json's true-GNSS-error entries."""
    errors = support_fix_errors(trace)
    threshold = detectable_bias_m(world)
    steps = {f"support-{s - 1}": int((e > threshold).sum()) for s, e in errors.items()}
    pooled = [float(v) for e in errors.values() for v in e]
    return {
        "gnss_multipath": world.scenario.world.gnss.multipath,
        "support_gnss_error_m": {
            f"support-{s - 1}": spread([float(v) for v in e]) for s, e in errors.items()
        },
        "supports_gnss_error_m": spread(pooled),
        "detectable_bias_m": round(threshold, 4),
        "gnss_error_steps": steps,
        "gnss_error_steps_total": int(sum(steps.values())),
    }
