"""The satellite sky: azimuth/elevation rows from a table, as ENU unit vectors."""

from __future__ import annotations

import csv
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np

from mission.config.errors import ScenarioError
from mission.config.settings import SkySettings

BUILTIN_TABLE = "sky_nagoya_2021-10-01.csv"
_COLUMNS = ("epoch_utc", "sv", "azimuth_deg", "elevation_deg")


@dataclass(frozen=True)
class Sky:
    """Satellites above the horizon at one epoch, with the elevation mask applied as a flag."""

    sv: tuple[str, ...]
    azimuth_rad: np.ndarray
    elevation_rad: np.ndarray
    above_mask: np.ndarray
    constellations: tuple[str, ...]

    @property
    def directions_enu(self) -> np.ndarray:
        """Unit vectors (S, 3) from the receiver toward each satellite, ENU."""
        cos_el = np.cos(self.elevation_rad)
        return np.column_stack(
            (
                np.sin(self.azimuth_rad) * cos_el,
                np.cos(self.azimuth_rad) * cos_el,
                np.sin(self.elevation_rad),
            )
        )

    @property
    def system(self) -> tuple[str, ...]:
        """One-letter constellation code of each satellite."""
        return tuple(s[0] for s in self.sv)

    def constellation_index(self) -> np.ndarray:
        """Index into ``constellations`` of each satellite's system."""
        return np.array([self.constellations.index(s) for s in self.system], dtype=int)


def table_path(settings: SkySettings) -> Path:
    """File holding the satellite table named by the settings."""
    if settings.table == "builtin":
        return Path(str(resources.files("mission.world") / "data" / BUILTIN_TABLE))
    return Path(settings.table)


def load_sky(settings: SkySettings) -> Sky:
    """Read the table's rows at the settings' epoch for the chosen constellations."""
    path = table_path(settings)
    rows = _read_rows(path)
    epoch = _normalise_epoch(settings.epoch_utc)
    chosen = [r for r in rows if r[0] == epoch and r[1][0] in settings.constellations]
    if not chosen:
        epochs = sorted({r[0] for r in rows})
        span = f"{epochs[0]} .. {epochs[-1]}" if epochs else "none"
        raise ScenarioError(
            str(path), "sky.epoch_utc", f"no satellites at {epoch} (table epochs: {span})"
        )
    chosen.sort(key=lambda r: r[1])
    azimuth = np.radians([r[2] for r in chosen])
    elevation = np.radians([r[3] for r in chosen])
    return Sky(
        sv=tuple(r[1] for r in chosen),
        azimuth_rad=azimuth,
        elevation_rad=elevation,
        above_mask=elevation >= np.radians(settings.elevation_mask_deg),
        constellations=tuple(settings.constellations),
    )


def _normalise_epoch(text: str) -> str:
    return text.replace("+00:00", "Z")


def _read_rows(path: Path) -> list[tuple[str, str, float, float]]:
    try:
        with path.open(newline="", encoding="utf-8") as handle:
            reader = csv.reader(handle)
            header = next(reader, None)
            if header is None or tuple(header[: len(_COLUMNS)]) != _COLUMNS:
                raise ScenarioError(
                    str(path), "line 1", f"header must start with {','.join(_COLUMNS)}"
                )
            rows = []
            for line_no, row in enumerate(reader, start=2):
                if not row:
                    continue
                rows.append(_parse_row(path, line_no, row))
            return rows
    except OSError as error:
        raise ScenarioError(str(path), "", f"cannot read: {error.strerror}") from None


def _parse_row(path: Path, line_no: int, row: list[str]) -> tuple[str, str, float, float]:
    if len(row) < len(_COLUMNS):
        raise ScenarioError(str(path), f"line {line_no}", f"expected {len(_COLUMNS)}+ columns")
    epoch, sv = row[0].strip(), row[1].strip()
    if not sv or not sv[0].isalpha():
        raise ScenarioError(str(path), f"line {line_no}, column sv", f"bad satellite id {sv!r}")
    try:
        azimuth, elevation = float(row[2]), float(row[3])
    except ValueError:
        raise ScenarioError(
            str(path), f"line {line_no}", "azimuth_deg and elevation_deg must be numbers"
        ) from None
    if not (0 <= azimuth <= 360 and -90 <= elevation <= 90):
        raise ScenarioError(str(path), f"line {line_no}", "azimuth or elevation out of range")
    return epoch, sv, azimuth, elevation
