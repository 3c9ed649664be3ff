"""Telemetry logs in pymavlink's format: 8-byte big-endian microsecond time, then the packet."""

from __future__ import annotations

import struct
from pathlib import Path


class TlogWriter:
    """Appends packets with their (simulated) timestamps; flush() makes them durable."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self._file = self.path.open("wb")

    def write(self, time_usec: int, packet: bytes) -> None:
        """One record."""
        self._file.write(struct.pack(">Q", max(0, int(time_usec))) + bytes(packet))

    def flush(self) -> None:
        """Push everything written so far to the file."""
        self._file.flush()

    def close(self) -> None:
        """Flush and close."""
        if not self._file.closed:
            self._file.flush()
            self._file.close()
