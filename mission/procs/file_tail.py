"""Reading a file as it grows: what it has gained since the last read, from where that read
stopped (a log relayed while a child writes it, a run's tlog and records followed live)."""

from __future__ import annotations

from pathlib import Path


class FileTail:
    """The bytes a growing file has gained; the caller says how many of them it used."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.offset = 0

    def new_bytes(self) -> bytes:
        """Everything after the offset (nothing if the file cannot be read now); the offset
        moves only by :meth:`advance`."""
        try:
            with self.path.open("rb") as handle:
                handle.seek(self.offset)
                return handle.read()
        except OSError:
            return b""

    def advance(self, count: int) -> None:
        """``count`` bytes of the last read are used: the next read starts after them."""
        self.offset += count

    def new_lines(self) -> list[bytes]:
        """The whole lines gained (a line still being written is read next time)."""
        data = self.new_bytes()
        end = data.rfind(b"\n") + 1
        self.advance(end)
        return data[:end].splitlines()
