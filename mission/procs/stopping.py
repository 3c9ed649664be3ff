"""Stopping child processes: SIGTERM to all at once, then SIGKILL to any still there after a
shared grace period; a stopped (frozen: SIGSTOP, a debugger) one is killed at once, since it
cannot act on SIGTERM until it is continued. Works on ``subprocess.Popen`` and on
:class:`~mission.procs.forked.ForkedProcess` alike (``pid``, ``poll``, ``terminate``,
``wait(timeout)``, ``kill``)."""

from __future__ import annotations

import subprocess
import time
from collections.abc import Iterable
from typing import Protocol


class Stoppable(Protocol):
    """What a child must offer to be stopped."""

    pid: int

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
            if is_frozen(process.pid):
                process.kill()
    deadline = time.monotonic() + grace_s
    for process in processes:
        try:
            process.wait(timeout=max(0.1, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def is_frozen(pid: int) -> bool:
    """Whether the process is stopped (state T or t in ``/proc/<pid>/stat``; False where that
    cannot be read)."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii", errors="replace") as stat:
            fields = stat.read().rsplit(")", 1)[1].split()
    except (OSError, IndexError):
        return False
    return bool(fields) and fields[0] in ("T", "t")
