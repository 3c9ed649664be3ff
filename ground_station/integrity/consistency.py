"""The integrity monitor's two consistency tests of a support's GNSS fix, each a chi-square
statistic T = nu^T S^-1 nu of a 3-vector innovation nu with its covariance S.

- **Motion**: the fix p_n against where the support's last estimate and its commanded motion
  put it, d_n = yhat_n + m_n: nu = p_n - d_n, S = Sigma_GNSS(p_n) + P_n + q^2 I, with P_n the
  last estimate's covariance and q the spread of where a vehicle ends against its command.
  It catches a step at its start.

Sigma_GNSS is the model's at p_n, or the receiver's own report (GPS_RAW_INT's h_acc and v_acc)
where that is worse: a receiver that knows it is poor widens its tests rather than being
excluded for noise it has announced.
- **Formation**: mu_n = p_n + r_n (where the support's fix and sighting put the work UAV)
  against the other supports' estimate of the work UAV, x_-n = (sum Sigma_m^-1)^-1 sum
  Sigma_m^-1 mu_m over the others m: nu = mu_n - x_-n, S = Sigma_n + (sum Sigma_m^-1)^-1. It
  catches a bias at any time the support sees the work UAV and another does too.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ground_station.estimation.fusion import SupportMeasurement
from ground_station.integrity.small import inverse3, quadratic3


@dataclass(frozen=True)
class Innovation:
    """nu, its covariance S, and T = nu^T S^-1 nu (computed once)."""

    nu: np.ndarray
    covariance: np.ndarray
    statistic: float = field(init=False)  # chi-square with 3 degrees of freedom, no fault

    def __post_init__(self) -> None:
        value = quadratic3(self.nu, inverse3(self.covariance))
        object.__setattr__(self, "statistic", value)

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
    gnss = support.sigma_gnss_tested_m2
    if support.fix_m is None or gnss is None:
        return None
    expected = previous_yhat + moved
    covariance = gnss + previous_covariance
    covariance[np.diag_indices(3)] += motion_sigma_m**2
    return Innovation(support.fix_m - expected, covariance)


class Formation:
    """The contributing supports' information (Sigma_n^-1 and Sigma_n^-1 mu_n), computed once
    a cycle, for estimates of the work UAV from any subset of them. With ``camera`` (Sigma_r
    of a relative vector), a support's test takes its camera's covariance at the relative
    vector the others predict where that is the larger: Sigma_r at the measured vector is
    smallest exactly when the measured range came out short."""

    def __init__(
        self,
        measurements: Sequence[SupportMeasurement],
        camera: Callable[[np.ndarray], np.ndarray] | None = None,
    ) -> None:
        self.camera = camera
        self.members = {m.name: m for m in measurements if m.contributes}
        self.sigma = {name: _tested_sigma(m) for name, m in self.members.items()}
        self.information = {name: inverse3(self.sigma[name]) for name in self.members}
        self.weighted = {name: self.information[name] @ m.mu for name, m in self.members.items()}

    def estimate(self, names: Sequence[str]) -> tuple[np.ndarray, np.ndarray] | None:
        """The work UAV's position from ``names`` (contributing supports), information-weighted,
        and its covariance (None with none)."""
        names = [name for name in names if name in self.members]
        if not names:
            return None
        information = sum(self.information[name] for name in names)
        covariance = inverse3(information)
        return covariance @ sum(self.weighted[name] for name in names), covariance

    def innovation(self, name: str, others: Sequence[str]) -> Innovation | None:
        """The formation test's innovation of ``name`` against ``others`` (None where it or no
        other contributes)."""
        support = self.members.get(name)
        if support is None:
            return None
        found = self.estimate([other for other in others if other != name])
        if found is None:
            return None
        position, covariance = found
        sigma = self.sigma[name]
        if self.camera is not None and support.sigma_relative_m2 is not None:
            assert support.fix_m is not None
            predicted = self.camera(position - support.fix_m)
            if np.trace(predicted) > np.trace(support.sigma_relative_m2):
                sigma = sigma - support.sigma_relative_m2 + predicted
        return Innovation(support.mu - position, sigma + covariance)


def _tested_sigma(support: SupportMeasurement) -> np.ndarray:
    """Sigma_n as the monitor tests it: Sigma_GNSS (or the receiver's own, worse) + Sigma_r."""
    gnss, relative = support.sigma_gnss_tested_m2, support.sigma_relative_m2
    assert gnss is not None and relative is not None
    return gnss + relative
