"""The sky and the sensors a support carries: the satellites' table and epoch, the GNSS
receiver's error, the camera's noise and range (paper 3.1)."""

from __future__ import annotations

from dataclasses import dataclass
from datetime import datetime

from mission.config.checks import as_parameter as _as_parameter
from mission.config.checks import non_negative as _non_negative
from mission.config.checks import positive as _positive
from mission.config.checks import require as _require
from mission.config.errors import FieldProblem


@dataclass(frozen=True)
class SkySettings:
    """Satellite sky: a table of azimuth/elevation rows and the epoch to use."""

    table: str
    epoch_utc: str
    elevation_mask_deg: float
    constellations: tuple[str, ...]

    def __post_init__(self) -> None:
        try:
            datetime.fromisoformat(self.epoch_utc.replace("Z", "+00:00"))
        except ValueError:
            raise FieldProblem(
                "epoch_utc", f"not an ISO-8601 time like 2021-10-01T03:00:00Z: {self.epoch_utc!r}"
            ) from None
        _require(
            0 <= self.elevation_mask_deg < 90,
            "elevation_mask_deg",
            f"must be in [0, 90), got {self.elevation_mask_deg}",
        )
        _require(bool(self.constellations), "constellations", "must name at least one")
        for i, code in enumerate(self.constellations):
            _require(
                len(code) == 1 and code.isalpha() and code.isupper(),
                f"constellations[{i}]",
                f"must be a one-letter system code such as G or R, got {code!r}",
            )


@dataclass(frozen=True)
class GnssSettings:
    """GNSS of a support UAV (paper 3.1.1)."""

    sigma_uere_m: float

    def __post_init__(self) -> None:
        _positive(self, "sigma_uere_m")
        _as_parameter("sigma_uere_m", self.sigma_uere_m, "SIM_GPS_UERE")


@dataclass(frozen=True)
class CameraSettings:
    """Relative observation by a support UAV's camera (paper 3.1.2).

    sigma_d(d) = sigma_d_a2_per_m d^2 + sigma_d_a1 d + sigma_d_a0_m.
    """

    sigma_d_a2_per_m: float
    sigma_d_a1: float
    sigma_d_a0_m: float
    sigma_elevation_deg: float
    sigma_azimuth_deg: float
    range_m: float

    def __post_init__(self) -> None:
        _non_negative(self, "sigma_d_a2_per_m", "sigma_d_a1")
        _positive(self, "sigma_d_a0_m", "sigma_elevation_deg", "sigma_azimuth_deg", "range_m")
        _as_parameter("range_m", self.range_m, "SIM_CAM_RANGE")
