"""The wind around the bridge: a mean wind, its Dryden turbulence, and what the
structure does to both (:mod:`mission.world.wind`)."""

from __future__ import annotations

from dataclasses import dataclass

from mission.config.checks import as_parameter as _as_parameter
from mission.config.checks import non_negative as _non_negative
from mission.config.checks import positive as _positive
from mission.config.checks import require as _require


@dataclass(frozen=True)
class WindSettings:
    """``speed_m_s`` at 6 m (20 ft, the height MIL-F-8785C's W20 refers to) from
    ``from_deg`` (clockwise from north, where it blows from, as a weather report says it)."""

    speed_m_s: float
    from_deg: float
    turbulence: (
        float  # Dryden's intensity sigma_w = turbulence x 0.1 x local speed (1: MIL-F-8785C)
    )
    shelter: float  # the local speed's fraction deep under a deck
    edge_gain: float  # the local speed's factor around a deck's edges and the piers
    edge_width_m: float  # how far the shelter fades in and the edges' speed-up reaches

    def __post_init__(self) -> None:
        _non_negative(self, "speed_m_s", "turbulence")
        _as_parameter("speed_m_s", self.speed_m_s, "SIM_WIND_SPD")
        _as_parameter("turbulence", self.turbulence, "SIM_WIND_DRYDEN")
        _require(0 <= self.from_deg < 360, "from_deg", "must be in [0, 360)")
        _require(0 <= self.shelter <= 1, "shelter", "must be in [0, 1]")
        _require(
            1 <= self.edge_gain <= 2,
            "edge_gain",
            "must be in [1, 2] (potential flow past a cylinder is twice as fast at its sides, "
            "the most a bluff body speeds a flow up)",
        )
        _positive(self, "edge_width_m")
