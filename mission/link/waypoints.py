"""QGC WPL 110 waypoint files: strict reading with precise errors, writing in mavwp's format.

Files written here are byte-identical to what pymavlink's ``mavwp`` saves for the same items,
so they round-trip through mavwp, MAVProxy and QGroundControl unchanged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.config.errors import InputError, read_text_file
from mission.link.mission_items import (
    COMMON_FIELDS,
    GLOBAL_FRAMES,
    MissionItem,
    to_int_field,
)
from mission.procs.atomic import write_text_atomically
from mission.world.frames import GeodeticFrame

HEADER = "QGC WPL 110"
COLUMNS = (
    "index",
    "current",
    "frame",
    "command",
    "param1",
    "param2",
    "param3",
    "param4",
    "x/latitude",
    "y/longitude",
    "z/altitude",
    "autocontinue",
)
RELATIVE_FRAMES = {
    mavlink2.MAV_FRAME_GLOBAL_RELATIVE_ALT,
    mavlink2.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
}


@dataclass(frozen=True)
class WaypointRow:
    """One line of a waypoint file (x, y in degrees for global frames)."""

    seq: int
    current: int
    frame: int
    command: int
    param1: float
    param2: float
    param3: float
    param4: float
    x: float
    y: float
    z: float
    autocontinue: int

    def to_item(self) -> MissionItem:
        """As the vehicle stores it (MISSION_ITEM_INT: 1e-7 degrees)."""
        common = {name: getattr(self, name) for name, _ in COMMON_FIELDS}
        x, y = to_int_field(self.x, self.frame), to_int_field(self.y, self.frame)
        return MissionItem(**common, x=x, y=y)


def format_waypoints(rows: list[WaypointRow]) -> str:
    """The file text, exactly as mavwp writes it."""
    lines = [HEADER]
    row_format = "%u\t%u\t%u\t%u\t%f\t%f\t%f\t%f\t%f\t%f\t%f\t%u"  # mavwp's own format
    for w in rows:
        fields = (
            w.seq,
            w.current,
            w.frame,
            w.command,
            w.param1,
            w.param2,
            w.param3,
            w.param4,
            w.x,
            w.y,
            w.z,
            w.autocontinue,
        )
        lines.append(row_format % fields)
    return "\n".join(lines) + "\n"


def write_waypoints(path: Path, rows: list[WaypointRow]) -> None:
    """Write a waypoint file atomically."""
    write_text_atomically(Path(path), format_waypoints(rows))


def read_waypoints(path: Path) -> list[WaypointRow]:
    """Read a QGC WPL 110 file; errors name the file, line and column."""
    path = Path(path)
    text = read_text_file(path)
    lines = text.splitlines()
    if not lines or lines[0].strip() != HEADER:
        raise InputError(str(path), "line 1", f"first line must be '{HEADER}'")
    rows: list[WaypointRow] = []
    for number, line in enumerate(lines[1:], start=2):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        rows.append(_parse_line(path, number, stripped.split()))
        if rows[-1].seq != len(rows) - 1:
            raise InputError(
                str(path),
                f"line {number}, column 1",
                f"index {rows[-1].seq} out of order (expected {len(rows) - 1})",
            )
    if not rows:
        raise InputError(str(path), "", "holds no waypoints")
    return rows


def _parse_line(path: Path, number: int, fields: list[str]) -> WaypointRow:
    if len(fields) != len(COLUMNS):
        raise InputError(
            str(path), f"line {number}", f"expected {len(COLUMNS)} values, got {len(fields)}"
        )
    values: list[float] = []
    for column, (name, text) in enumerate(zip(COLUMNS, fields), start=1):
        where = f"line {number}, column {column} ({name})"
        integer = column in (1, 2, 3, 4, 12)
        try:
            value = int(text) if integer else float(text)
        except ValueError:
            kind = "an integer" if integer else "a number"
            raise InputError(str(path), where, f"expected {kind}, got {text!r}") from None
        if not integer and not math.isfinite(value):
            raise InputError(str(path), where, f"must be finite, got {text!r}")
        if integer and value < 0:
            raise InputError(str(path), where, f"must not be negative, got {text}")
        values.append(value)
    row = WaypointRow(
        int(values[0]),
        int(values[1]),
        int(values[2]),
        int(values[3]),
        *values[4:11],
        int(values[11]),
    )
    if row.frame in GLOBAL_FRAMES:
        if not -90 <= row.x <= 90:
            raise InputError(
                str(path),
                f"line {number}, column 9 (x/latitude)",
                f"latitude out of range: {row.x}",
            )
        if not -180 <= row.y <= 180:
            raise InputError(
                str(path),
                f"line {number}, column 10 (y/longitude)",
                f"longitude out of range: {row.y}",
            )
    return row


def row_position_enu(row: WaypointRow, frame: GeodeticFrame) -> np.ndarray:
    """ENU position of a global waypoint (relative altitudes measured from the anchor)."""
    alt = row.z + (frame.anchor.alt_m if row.frame in RELATIVE_FRAMES else 0.0)
    return frame.to_enu(row.x, row.y, alt)


def waypoint_rows_from_enu(
    points: np.ndarray, frame: GeodeticFrame, acceptance_m: float
) -> list[WaypointRow]:
    """Home (seq 0, ArduPilot's convention) plus one NAV_WAYPOINT per point, relative altitude.

    Latitude and longitude are written with mavwp's six decimals (about 0.1 m); the positions
    the file holds are the waypoints, so everyone who reads the file agrees on them.
    """
    rows = []
    for seq, point in enumerate([points[0], *points]):
        lat, lon, alt = frame.to_geodetic(point)
        rows.append(
            WaypointRow(
                seq,
                1 if seq == 0 else 0,
                mavlink2.MAV_FRAME_GLOBAL_RELATIVE_ALT,
                mavlink2.MAV_CMD_NAV_WAYPOINT,
                0.0,
                acceptance_m if seq else 0.0,
                0.0,
                0.0,
                round(lat, 6),
                round(lon, 6),
                round(alt - frame.anchor.alt_m, 3),
                1,
            )
        )
    return rows
