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

import numpy as np

from ground_station.integrity.small import inverse3


def no_fault_radius(covariance: np.ndarray, k2: float) -> float:
    """sqrt(k2 lambda_max(P))."""
    return float(np.sqrt(k2 * max(float(np.linalg.eigvalsh(covariance)[-1]), 0.0)))


def detectable_bias(covariance: np.ndarray, detectable: float) -> float:
    """The minimal detectable bias of a test with innovation covariance ``covariance`` in its
    worst direction: sqrt(lambda* lambda_max(S))."""
    return float(np.sqrt(detectable * max(float(np.linalg.eigvalsh(covariance)[-1]), 0.0)))


def fault_shift(
    covariance: np.ndarray,
    information: dict[str, np.ndarray],
    sigma: dict[str, np.ndarray],
    detectable: float,
    lone_bound: float | None,
) -> float:
    """The largest shift an undetected fault in one fused support can make in an estimate
    with ``covariance`` fused from ``information`` (Sigma_m^-1 by support): ||W_m|| MDB_m,
    W_m = P Sigma_m^-1, MDB_m the formation test's against the others (``sigma``: each
    Sigma_m as tested), or, fused alone, ``lone_bound`` (its motion test's; None: unbounded).
    """
    shift = 0.0
    for name, inverse in information.items():
        others = [other for other in information if other != name]
        if others:
            rest = inverse3(sum(information[other] for other in others))
            bound = detectable_bias(sigma[name] + rest, detectable)
        else:
            bound = float("inf") if lone_bound is None else lone_bound
        shift = max(shift, float(np.linalg.norm(covariance @ inverse, 2)) * bound)
    return shift
