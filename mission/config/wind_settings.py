"""The wind around the bridge: a mean wind and its profile with height, the run's Dryden
turbulence, and what the structure does to both (:mod:`mission.world.wind`)."""

from __future__ import annotations

from dataclasses import dataclass

from mission.config.checks import as_parameter as _as_parameter
from mission.config.checks import non_negative as _non_negative
from mission.config.checks import positive as _positive
from mission.config.checks import require as _require

MAX_ROUGHNESS_M = 0.3  # EN 1991-1-4's terrain category III (villages, forest)
MAX_WAKE_GUST_GAIN = 3.0


@dataclass(frozen=True)
class WindSettings:
    """``speed_m_s`` at 6 m (20 ft, the height MIL-F-8785C's W20 refers to) from
    ``from_deg`` (clockwise from north, where it blows from, as a weather report says it)."""

    speed_m_s: float
    from_deg: float
    turbulence: float  # Dryden's intensity sigma_w = turbulence x 0.1 x W20 (1: MIL-F-8785C)
    roughness_length_m: float  # z0 of the log law the mean speed follows with height
    shelter: float  # the local speed's fraction deep under a deck
    edge_gain: float  # the local speed's factor around a deck's edges and the piers
    edge_width_m: float  # how far the shelter fades in and the edges' speed-up reaches
    wake_gust_gain: float  # the gusts' sigma in a deck's near wake over the free stream's

    def __post_init__(self) -> None:
        _non_negative(self, "speed_m_s", "turbulence")
        _as_parameter("speed_m_s", self.speed_m_s, "SIM_WIND_SPD")
        _as_parameter("turbulence", self.turbulence, "SIM_WIND_DRYDEN")
        _require(0 <= self.from_deg < 360, "from_deg", "must be in [0, 360)")
        _require(
            0 < self.roughness_length_m <= MAX_ROUGHNESS_M,
            "roughness_length_m",
            f"must be in (0, {MAX_ROUGHNESS_M:g}] m (EN 1991-1-4's terrain categories 0 to III, "
            f"sea to villages; the log law is held below 3 m), got {self.roughness_length_m:g}",
        )
        _require(0 <= self.shelter <= 1, "shelter", "must be in [0, 1]")
        _require(
            1 <= self.edge_gain <= 2,
            "edge_gain",
            "must be in [1, 2] (potential flow past a cylinder is twice as fast at its sides, "
            "the most a bluff body speeds a flow up)",
        )
        _positive(self, "edge_width_m")
        _require(
            1 <= self.wake_gust_gain <= MAX_WAKE_GUST_GAIN,
            "wake_gust_gain",
            f"must be in [1, {MAX_WAKE_GUST_GAIN:g}] (a bluff body's wake raises the "
            f"turbulence, PRIME's building wake by 1.7), got {self.wake_gust_gain:g}",
        )
