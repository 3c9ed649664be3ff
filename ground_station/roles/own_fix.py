"""The work UAV's own GNSS fix (``roles.policy: dynamic``): judged each cycle, fused with the
supports' relative estimate where it is trustworthy, else ignored, and the verdict recorded.

A fix is trusted when all hold, in this order (the first that fails is the reason recorded):

1. ``no fix``: the receiver reports a 3-D fix (under the deck it mostly has none);
2. ``shadow``: the ground station's sky model predicts a fix at that position (a fix where the
   structure should block too many satellites is a reflection's);
3. ``map``: the map G (learned in AC, the sky's prediction sigma_0 in NAC) expects an error of
   at most ``own_fix_max_sigma_m`` there (multipath the supports have met is learned here);
4. ``disagrees``: where the supports give a relative estimate, the fix lies within
   ``own_fix_agreement_sigmas`` standard deviations of it (the Mahalanobis distance under
   the fix's covariance plus the relative estimate's).

G's sigma is the 3-D one (sqrt of the covariance's trace, as sigma_0 is): the fix's covariance
is taken as isotropic, a third of its square on each axis.

Trusted, the estimate is the two combined by their information (the relative estimate's
covariance from the consistent supports' likelihoods), or the fix alone where the supports
give none: the work UAV is then not blind.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ground_station.estimation.fusion import FusionResult
from ground_station.estimation.gnss_map import LocalizabilityMap
from mission.config.role_settings import RoleSettings
from mission.world.model import KnownWorld

USED = "used"


@dataclass(frozen=True)
class OwnFix:
    """One cycle's verdict on the work UAV's own fix: used or why not, the sigma G expects at
    it (m) and its distance from the relative estimate (in sigmas); None where not reached."""

    reason: str
    sigma_m: float | None = None
    distance_sigmas: float | None = None
    # a used verdict's: the supports' relative estimate's covariance (None where they give
    # none), what combined_estimate weighs the fix against; not recorded
    relative_cov: np.ndarray | None = field(default=None, compare=False, repr=False)

    @property
    def used(self) -> bool:
        """Whether the fix went into xhat."""
        return self.reason == USED

    def record(self) -> dict[str, object]:
        """The verdict as the cycle's record carries it."""
        rounded = {
            "sigma_m": None if self.sigma_m is None else round(self.sigma_m, 4),
            "distance_sigmas": None
            if self.distance_sigmas is None
            else round(self.distance_sigmas, 3),
        }
        return {"used": self.used, "reason": self.reason, **rounded}


def relative_covariance(fusion: FusionResult) -> np.ndarray | None:
    """The covariance of the supports' relative estimate: the inverse of the sum of the
    consistent supports' information (None when blind)."""
    if fusion.xhat is None or not fusion.densities:
        return None
    inverses = np.linalg.inv(np.array([d.factor @ d.factor.T for d in fusion.densities]))
    return np.linalg.inv(sum(inverses))


def own_covariance(sigma_m: float) -> np.ndarray:
    """The fix's covariance for G's 3-D sigma: isotropic, sigma^2 / 3 on each axis."""
    return np.eye(3) * sigma_m**2 / 3


def judge(
    fix: np.ndarray | None,
    fusion: FusionResult,
    g: LocalizabilityMap,
    world: KnownWorld,
    settings: RoleSettings,
) -> OwnFix:
    """The verdict on ``fix`` (ENU; None without a 3-D fix) for this cycle."""
    if fix is None:
        return OwnFix("no fix")
    if not world.gnss.has_fix(fix[None])[0]:
        return OwnFix("shadow")
    sigma = float(g.smoothed(fix[None])[0])
    if sigma > settings.own_fix_max_sigma_m:
        return OwnFix("map", sigma)
    covariance = relative_covariance(fusion)
    if covariance is None:
        return OwnFix(USED, sigma)
    gap = fix - fusion.xhat
    combined = covariance + own_covariance(sigma)
    distance = float(np.sqrt(gap @ np.linalg.solve(combined, gap)))
    if distance > settings.own_fix_agreement_sigmas:
        return OwnFix("disagrees", sigma, distance)
    return OwnFix(USED, sigma, distance, covariance)


def combined_estimate(fix: np.ndarray, verdict: OwnFix, fusion: FusionResult) -> np.ndarray:
    """The work UAV's estimate from a trusted ``fix``: with the relative estimate by their
    information, or the fix alone where the supports give none."""
    covariance = verdict.relative_cov
    if covariance is None:
        assert fusion.xhat is None, "a verdict from judge() on this fusion carries its covariance"
        return np.asarray(fix, dtype=float).copy()
    assert verdict.sigma_m is not None and fusion.xhat is not None
    own_information = np.linalg.inv(own_covariance(verdict.sigma_m))
    relative_information = np.linalg.inv(covariance)
    total = own_information + relative_information
    return np.linalg.solve(total, own_information @ fix + relative_information @ fusion.xhat)
