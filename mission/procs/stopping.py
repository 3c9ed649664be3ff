"""Stopping child processes: SIGTERM to all at once, then SIGKILL to any still there after a
shared grace period. Works on ``subprocess.Popen`` and on :class:`~mission.procs.forked.
ForkedProcess` alike (``poll``, ``terminate``, ``wait(timeout)``, ``kill``)."""

from __future__ import annotations

import subprocess
import time
from collections.abc import Iterable
from typing import Protocol


class Stoppable(Protocol):
    """What a child must offer to be stopped."""

    def poll(self) -> int | None: ...

    def terminate(self) -> None: ...

    def kill(self) -> None: ...

    def wait(self, timeout: float | None = None) -> int: ...


def stop_processes(processes: Iterable[Stoppable], grace_s: float) -> None:
    """Ask every running one to stop, wait up to ``grace_s`` in all, then kill the rest; every
    one has been waited for on return (no zombie)."""
    processes = list(processes)
    for process in processes:
        if process.poll() is None:
            process.terminate()
    deadline = time.monotonic() + grace_s
    for process in processes:
        try:
            process.wait(timeout=max(0.1, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
