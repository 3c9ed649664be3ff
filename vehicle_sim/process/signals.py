"""A vehicle process's signals: SIGTERM and SIGINT end its loop cleanly, and wake it at once
from its wait for packets."""

from __future__ import annotations

import contextlib
import signal
import socket
from collections.abc import Callable, Iterator


@contextlib.contextmanager
def signal_wakeup() -> Iterator[socket.socket]:
    """A socket that becomes readable when a signal arrives (signal.set_wakeup_fd); the
    previous wakeup fd is restored after. Outside the main thread, one that never wakes."""
    reader, writer = socket.socketpair()
    reader.setblocking(False)
    writer.setblocking(False)
    try:
        previous = signal.set_wakeup_fd(writer.fileno(), warn_on_full_buffer=False)
    except ValueError:  # not the main thread
        previous = None
    try:
        yield reader
    finally:
        if previous is not None:
            signal.set_wakeup_fd(previous)
        reader.close()
        writer.close()


def install_signal_handlers(stop: Callable[..., None], die_with_parent: bool) -> None:
    """SIGTERM and SIGINT end the loop cleanly; optionally die with the parent (Linux)."""
    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, stop)
    if die_with_parent:
        from mission.procs.process_life import die_with_parent as arrange

        arrange()
