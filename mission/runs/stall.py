"""A run that stops making progress is stopped: the stall watchdog of ``mission run``.

A run makes progress while its ground station's tlog grows: every control cycle logs the
estimates and setpoints it sends and the telemetry it reads, in lockstep and in real time.
A ground station stuck in one place (a solver that never returns, a wait that never ends)
logs nothing; after ``limit_s`` seconds of wall time without a byte the run is stalled.
Starting up counts from the watch's start; compiling the support MPC (a first run on a
machine: some 12 s here, minutes on a loaded one) does not count.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

DEFAULT_STALL_S = 180.0  # wall seconds; a lockstep cycle takes ~20 ms, a start-up a few s


class StallWatch:
    """Seconds of wall time since ``progress`` (a file) last grew."""

    def __init__(
        self, progress: Path, limit_s: float, clock: Callable[[], float] = time.monotonic
    ) -> None:
        self.progress = progress
        self.limit_s = limit_s  # 0: never stalled
        self.clock = clock
        self.size = -1
        self.since = clock()

    def stalled(self, paused: bool = False) -> bool:
        """True once the file has not grown for the limit; ``paused`` (compiling): the wait
        starts again."""
        now = self.clock()
        try:
            size = self.progress.stat().st_size
        except OSError:
            size = -1
        if paused or size != self.size:
            self.size, self.since = size, now
            return False
        return self.limit_s > 0 and now - self.since >= self.limit_s
