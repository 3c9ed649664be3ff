"""Reading a run's files as they grow: the tlog, the records and G's snapshots.

Each reader keeps its place and returns only what is new and whole, so the same code replays a
finished run (one read) and follows a running one (a read every fraction of a second). None of
this imports Rerun.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import numpy as np

os.environ.setdefault("MAVLINK20", "1")
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.analysis.metrics import scan_records
from mission.analysis.record_schema import parse_record
from mission.procs.file_tail import FileTail

VIEWED_IDS = frozenset(
    {
        mavlink2.MAVLINK_MSG_ID_SIM_STATE,
        mavlink2.MAVLINK_MSG_ID_SYSTEM_TIME,
        mavlink2.MAVLINK_MSG_ID_TIMESYNC,
        mavlink2.MAVLINK_MSG_ID_GPS_RAW_INT,
        mavlink2.MAVLINK_MSG_ID_LANDING_TARGET,
    }
)
STATION_SYSTEM_ID = 255  # the ground station's packets (requests, commands) are skipped
SYSTEM_TIME_ID = mavlink2.MAVLINK_MSG_ID_SYSTEM_TIME
SNAPSHOT_NAME = re.compile(r"^G_(\d+|initial|final)\.npy$")  # g/ files of G


class TlogTail:
    """The messages of the kinds the view shows, from where the last read stopped."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self._file = FileTail(path)
        self._parser = mavlink2.MAVLink(None)
        self._station_tick_seen = False

    def read(self) -> list[Any]:
        """The new messages, each with its ``_timestamp`` (seconds of the tlog's clock)."""
        data = self._file.new_bytes()
        records, end, clean = scan_records(data, VIEWED_IDS)
        # past a damaged record nothing can be framed again: stop there for good
        self._file.advance(end if clean else len(data))
        messages = []
        for usec, packet in records:
            station = packet[5] == STATION_SYSTEM_ID  # its own: only its first clock tick
            if station and (self._station_tick_seen or _message_id(packet) != SYSTEM_TIME_ID):
                continue
            try:
                message = self._parser.decode(bytearray(packet))
            except mavlink2.MAVError:
                continue
            message._timestamp = usec * 1.0e-6
            messages.append(message)
            if packet[5] == STATION_SYSTEM_ID and message.time_boot_ms > 0:
                self._station_tick_seen = True  # lockstep: the view needs no more of these
        return messages


class RecordsTail:
    """The ground station's new per-cycle records (whole lines only)."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self._file = FileTail(path)

    def read(self) -> list[dict[str, Any]]:
        records = []
        for line in self._file.new_lines():
            record, _ = parse_record(line)  # a line that is not a record is not shown
            if record is not None:
                records.append(record)
        return records


class SnapshotTail:
    """G's snapshots (``g/G_<cycles>.npy``, ``G_initial``, ``G_final``) not read yet, in the
    order the ground station wrote them; a file still being written is read next time."""

    def __init__(self, g_dir: Path, shape: tuple[int, ...]) -> None:
        self.g_dir = g_dir
        self.shape = shape
        self._done: set[str] = set()

    def read(self, cycles_seen: int, final: bool) -> list[tuple[str, np.ndarray]]:
        """(label, values) of the new snapshots: ``initial``, a number of cycles (only up to
        ``cycles_seen``, whose times are known), and ``final`` once the run is over."""
        try:
            names = sorted(p.name for p in self.g_dir.iterdir())
        except OSError:
            return []
        found = []
        for name in names:
            match = SNAPSHOT_NAME.match(name)
            if match is None or name in self._done:
                continue
            label = match.group(1)
            if (label == "final" and not final) or (label.isdigit() and int(label) > cycles_seen):
                continue
            values = _load(self.g_dir / name, self.shape)
            if values is not None:
                self._done.add(name)
                found.append((label, values))
        order = {"initial": -1, "final": float("inf")}
        return sorted(found, key=lambda item: order.get(item[0]) or int(item[0]))


def _message_id(packet: bytes) -> int:
    return int.from_bytes(packet[7:10], "little")


def _load(path: Path, shape: tuple[int, ...]) -> np.ndarray | None:
    try:
        values = np.load(path)
    except (OSError, ValueError, EOFError):
        return None
    return values.reshape(shape) if values.size == int(np.prod(shape)) else None
