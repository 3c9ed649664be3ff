"""Who does what (issue 33, the paper's third open question): the work UAV on its own GNSS
where it can (:mod:`ground_station.roles`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from mission.config.checks import positive as _positive


@dataclass(frozen=True)
class RoleSettings:
    """``policy: fixed`` (the paper): the work UAV is localized by the supports alone, its own
    GNSS fix ignored. ``dynamic``: the ground station also judges the work UAV's own fix each
    cycle and fuses it when it is trustworthy: a 3-D fix where the map G (learned, or the sky's
    prediction) expects at most ``own_fix_max_sigma_m``, and, where the supports give a
    relative estimate, within ``own_fix_agreement_sigmas`` standard deviations of it."""

    policy: Literal["fixed", "dynamic"]
    own_fix_max_sigma_m: float
    own_fix_agreement_sigmas: float

    def __post_init__(self) -> None:
        _positive(self, "own_fix_max_sigma_m", "own_fix_agreement_sigmas")
