"""How far a run has got, on one line of a terminal that rewrites itself: the control cycle,
the simulated time and the real-time factor, read from the ground station's records as they
grow. Quiet where stderr is not a terminal (a pipe, a log file, a notebook, a study's run)."""

from __future__ import annotations

import re
import sys
import time
from pathlib import Path
from typing import TextIO

from mission.procs.file_tail import FileTail

_RECORD_START = re.compile(rb'^\{"t": (?P<t>[\d.]+),')  # one record per control cycle
EVERY_S = 0.5  # at most two updates a second


class RunProgress:
    """The line ``cycle K, T of LIMIT s simulated, Fx real time`` while a run flies."""

    def __init__(self, records: Path, timeout_s: float, stream: TextIO | None = None) -> None:
        self.stream = sys.stderr if stream is None else stream
        self.shown = False
        self._timeout_s = timeout_s
        self._file = FileTail(records)
        self._first_wall: float | None = None
        self._last_shown = 0.0
        self._width = 0
        self._cycles = 0

    @staticmethod
    def wanted(stream: TextIO | None = None) -> bool:
        """Whether ``stream`` (stderr) is a terminal, where a line that rewrites itself reads."""
        stream = sys.stderr if stream is None else stream
        return hasattr(stream, "isatty") and stream.isatty()

    def poll(self) -> None:
        """Show the latest cycle, at most every EVERY_S of wall time."""
        lines = self._file.new_lines()
        now = time.monotonic()
        self._cycles += len(lines)
        latest = next((m for m in map(_RECORD_START.match, reversed(lines)) if m), None)
        if latest is None:
            return
        if self._first_wall is None:  # flying starts: start-up and compiling left out
            self._first_wall = now
        if now - self._last_shown < EVERY_S:
            return
        self._last_shown = now
        t, cycle = float(latest["t"]), self._cycles
        flown = now - self._first_wall
        speed = f", {t / flown:.0f}x real time" if flown > 1.0 else ""
        self._show(f"cycle {cycle}, {t:.1f} of {self._timeout_s:g} s simulated{speed}")

    def clear(self) -> None:
        """Remove the line, so that what follows starts on a clean one."""
        if self.shown:
            self.stream.write("\r" + " " * self._width + "\r")
            self.stream.flush()
            self.shown = False

    def _show(self, text: str) -> None:
        self._width = max(self._width, len(text))
        self.stream.write("\r" + text.ljust(self._width))
        self.stream.flush()
        self.shown = True
