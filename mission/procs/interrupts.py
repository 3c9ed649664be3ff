"""Ctrl-C and SIGTERM as a stop request that cannot be lost.

A handler that only raises KeyboardInterrupt loses the request when the signal lands where
Python swallows exceptions: an at-fork callback (logging's lock release after ``os.fork``), a
``__del__``, a weakref callback. A run interrupted that way flew on to the end and wrote its
summary after its study had been cancelled. :class:`StopRequest` also remembers the request,
and the loops that wait (a run's supervision, the local engine's) call :meth:`check`.
"""

from __future__ import annotations

import signal
from types import FrameType, TracebackType

SIGNALS = (signal.SIGINT, signal.SIGTERM)


class StopRequest:
    """While entered, SIGINT and SIGTERM raise KeyboardInterrupt and are remembered, even
    where the process was started with SIGINT ignored (a background job); the previous
    handlers come back on exit."""

    def __init__(self) -> None:
        self.requested = False
        self._previous: dict[int, object] = {}

    def __enter__(self) -> StopRequest:
        for number in SIGNALS:
            self._previous[number] = signal.signal(number, self._handle)
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> None:
        for number, handler in self._previous.items():
            signal.signal(number, handler)  # type: ignore[arg-type]
        self._previous.clear()

    def check(self) -> None:
        """Raise KeyboardInterrupt if a stop was asked for (its exception may have been lost)."""
        if self.requested:
            raise KeyboardInterrupt

    def _handle(self, number: int, frame: FrameType | None) -> None:
        self.requested = True
        raise KeyboardInterrupt
