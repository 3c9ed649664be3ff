"""How the world shapes the GNSS signals a receiver gets: the multipath model and
the constants of reflections and code tracking (:mod:`mission.world.multipath`).

These belong to the simulated world only: the ground station's scenario carries the defaults
(:func:`mission.world.model.without_multipath`), never the model a run's vehicles use.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from mission.config.checks import require as _require

MultipathModel = Literal["zones", "geometry", "both"]
Surface = Literal["concrete", "ground", "water"]
Solution = Literal["rtk", "code"]


@dataclass(frozen=True)
class ReflectionAmplitudes:
    """A reflected signal's field amplitude relative to the direct one, by surface.

    Defaults (docs/model.md, "Multipath from geometry"): the Fresnel reflection of a
    circularly polarised L1 wave at 30 degrees' grazing, sqrt((|G_h|^2 + |G_v|^2) / 2), with the
    permittivities of ITU-R P.2040 (concrete 5.24, medium dry ground 15 f^-0.1 and their
    conductivities) and a Debye model of fresh water at 20 C (79.4 - 6.9j)."""

    concrete: float
    ground: float
    water: float

    def __post_init__(self) -> None:
        for name in ("concrete", "ground", "water"):
            value = getattr(self, name)
            _require(
                0 <= value <= 1,
                name,
                f"a reflection coefficient must be in [0, 1] (a passive surface returns no "
                f"more than it receives), got {value:g}",
            )

    def of(self, surface: Surface) -> float:
        """The amplitude of ``surface``."""
        return float(getattr(self, surface))


@dataclass(frozen=True)
class SignalSettings:
    """``multipath``: where GNSS errors come from. ``zones``: the scenario's boxes, each with a
    constant offset (the paper); ``geometry``: reflections off the structure and the ground,
    tracked by the receiver and solved as it solves them; ``both``: the two added."""

    multipath: MultipathModel
    solution: Solution  # rtk: code errors count only where a reflection is tracked (the
    # ambiguities cannot be fixed; docs/model.md); code: a code receiver's, always
    structure_surface: Surface  # what the structure's faces are made of
    ground_surface: Surface  # what the plane z = 0 is: ground, or water under a bridge
    amplitude: ReflectionAmplitudes
    correlator_spacing_chips: float  # early-minus-late spacing (0.1: a narrow correlator)
    cn0_open_sky_dbhz: float  # carrier-to-noise density of a direct signal
    cn0_floor_dbhz: float  # below this a signal is not tracked
    antenna_below_horizon_db: float  # antenna gain for signals arriving from below its horizon

    def __post_init__(self) -> None:
        _require(
            0 < self.correlator_spacing_chips <= 1,
            "correlator_spacing_chips",
            f"must be in (0, 1] chips (1: a standard correlator, 0.1: a narrow one), got "
            f"{self.correlator_spacing_chips:g}",
        )
        _require(
            20 <= self.cn0_open_sky_dbhz <= 60,
            "cn0_open_sky_dbhz",
            f"must be in [20, 60] dB-Hz (L1 signals arrive at 40-50), got "
            f"{self.cn0_open_sky_dbhz:g}",
        )
        _require(
            0 <= self.cn0_floor_dbhz < self.cn0_open_sky_dbhz,
            "cn0_floor_dbhz",
            f"must be in [0, cn0_open_sky_dbhz) (a receiver that cannot track a direct signal "
            f"has no fix), got {self.cn0_floor_dbhz:g}",
        )
        _require(
            -60 <= self.antenna_below_horizon_db <= 0,
            "antenna_below_horizon_db",
            f"must be in [-60, 0] dB (an antenna does not amplify from below), got "
            f"{self.antenna_below_horizon_db:g}",
        )

    @property
    def uses_zones(self) -> bool:
        """True when the scenario's zones bias fixes."""
        return self.multipath in ("zones", "both")

    @property
    def uses_geometry(self) -> bool:
        """True when reflections off the structure and the ground bias fixes."""
        return self.multipath in ("geometry", "both")
