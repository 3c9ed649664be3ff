"""Protection radii: for each estimate, a radius its error stays within but with probability
``missed_detection``, as ARAIM bounds a position (no fault, or one fault too small to detect).

- **No fault**: the error e ~ N(0, P) stays within sqrt(k2 lambda_max(P)) but with probability
  at most alpha, k2 the chi-square (3 dof) quantile at alpha = ``missed_detection``.
- **One undetected fault**: a bias b_m in support m's measurement that its test misses with
  probability at least ``missed_detection`` can be as large as its minimal detectable bias
  MDB_m = sqrt(lambda* lambda_max(S_m)) (S_m that test's innovation covariance); it moves an
  information-weighted estimate by W_m b_m, W_m = P Sigma_m^-1, at most ||W_m|| MDB_m.

The work UAV's radius is the first plus the largest second over the supports fused; a
support's is the first for its estimate's covariance plus the bias its estimate could carry
undetected: its own fix's (the motion test's MDB) where the fix went into it, or the work UAV's
fault term where the formation placed it.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ground_station.fusion import SupportMeasurement


def no_fault_radius(covariance: np.ndarray, k2: float) -> float:
    """sqrt(k2 lambda_max(P))."""
    return float(np.sqrt(k2 * max(float(np.linalg.eigvalsh(covariance)[-1]), 0.0)))


def detectable_bias(covariance: np.ndarray, detectable: float) -> float:
    """The minimal detectable bias of a test with innovation covariance ``covariance`` in its
    worst direction: sqrt(lambda* lambda_max(S))."""
    return float(np.sqrt(detectable * max(float(np.linalg.eigvalsh(covariance)[-1]), 0.0)))


def fused_protection(
    used: Sequence[SupportMeasurement],
    detectable: float,
    k2: float,
    motion_detectable: dict[str, float],
) -> tuple[float, float] | None:
    """(the work UAV's protection radius, its fault term) from the supports fused (None:
    none). Each support's undetected bias is bounded by its formation test's MDB against the
    others, or, fused alone, by its motion test's (infinite without one)."""
    if not used:
        return None
    inverses = [np.linalg.inv(m.sigma) for m in used]
    covariance = np.linalg.inv(sum(inverses))
    fault = 0.0
    for i, m in enumerate(used):
        others = [inverse for j, inverse in enumerate(inverses) if j != i]
        if others:
            bound = detectable_bias(m.sigma + np.linalg.inv(sum(others)), detectable)
        else:
            bound = motion_detectable.get(m.name, float("inf"))
        gain = float(np.linalg.norm(covariance @ inverses[i], 2))
        fault = max(fault, gain * bound)
    return no_fault_radius(covariance, k2) + fault, fault
