"""The integrity monitor's two consistency tests of a support's GNSS fix, each a chi-square
statistic T = nu^T S^-1 nu of a 3-vector innovation nu with its covariance S.

- **Motion**: the fix p_n against where the support's last estimate and its commanded motion
  put it, d_n = yhat_n + m_n: nu = p_n - d_n, S = Sigma_GNSS(p_n) + P_n + q^2 I, with P_n the
  last estimate's covariance and q the spread of where a vehicle ends against its command.
  It catches a step at its start.
- **Formation**: mu_n = p_n + r_n (where the support's fix and sighting put the work UAV)
  against the other supports' estimate of the work UAV, x_-n = (sum Sigma_m^-1)^-1 sum
  Sigma_m^-1 mu_m over the others m: nu = mu_n - x_-n, S = Sigma_n + (sum Sigma_m^-1)^-1. It
  catches a bias at any time the support sees the work UAV and another does too.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ground_station.fusion import SupportMeasurement


@dataclass(frozen=True)
class Innovation:
    """nu, its covariance S, and T = nu^T S^-1 nu."""

    nu: np.ndarray
    covariance: np.ndarray

    @property
    def statistic(self) -> float:
        """T, chi-square with 3 degrees of freedom without a fault."""
        return float(self.nu @ np.linalg.solve(self.covariance, self.nu))

    @property
    def size_m(self) -> float:
        """|nu|: how far the fix is from where it was expected."""
        return float(np.linalg.norm(self.nu))


def motion_innovation(
    support: SupportMeasurement,
    previous_yhat: np.ndarray,
    moved: np.ndarray,
    previous_covariance: np.ndarray,
    motion_sigma_m: float,
) -> Innovation | None:
    """The motion test's innovation (None without a fix)."""
    if support.fix_m is None or support.sigma_gnss_m2 is None:
        return None
    expected = previous_yhat + moved
    covariance = support.sigma_gnss_m2 + previous_covariance + motion_sigma_m**2 * np.eye(3)
    return Innovation(support.fix_m - expected, covariance)


def formation_estimate(
    others: Sequence[SupportMeasurement],
) -> tuple[np.ndarray, np.ndarray] | None:
    """The work UAV's position from the given contributing supports, information-weighted,
    and its covariance (None with none)."""
    usable = [m for m in others if m.contributes]
    if not usable:
        return None
    information = np.zeros((3, 3))
    weighted = np.zeros(3)
    for m in usable:
        inverse = np.linalg.inv(m.sigma)
        information += inverse
        weighted += inverse @ m.mu
    covariance = np.linalg.inv(information)
    return covariance @ weighted, covariance


def formation_innovation(
    support: SupportMeasurement, others: Sequence[SupportMeasurement]
) -> Innovation | None:
    """The formation test's innovation (None where the support or no other contributes)."""
    if not support.contributes:
        return None
    estimate = formation_estimate([m for m in others if m.name != support.name])
    if estimate is None:
        return None
    position, covariance = estimate
    return Innovation(support.mu - position, support.sigma + covariance)
