"""A process's life among the project's processes: its name, dying with its parent, and a
heap frozen once it is set up."""

from __future__ import annotations

import os
import sys

PARENT_PID_VARIABLE = "MISSION_PARENT_PID"


def child_environment() -> dict[str, str]:
    """The environment for a child that calls :func:`die_with_parent`: names this process."""
    return {**os.environ, PARENT_PID_VARIABLE: str(os.getpid())}


def freeze_startup_heap() -> None:
    """Exempt everything allocated so far (modules, world, solver) from garbage collection.

    A long-running process calls this once it is set up: full collections then skip the
    ~10^5 objects of numpy, pymavlink and casadi, and so does the exit (50 ms -> 10 ms)."""
    import gc

    gc.freeze()


PR_SET_PDEATHSIG = 1  # prctl options (linux/prctl.h)
PR_SET_NAME = 15


def _prctl(option: int, value: int | bytes) -> None:
    """Linux's prctl(option, value); nothing elsewhere or where libc will not say."""
    import contextlib
    import ctypes

    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            ctypes.CDLL("libc.so.6", use_errno=True).prctl(option, value, 0, 0, 0)


def name_this_process(name: str) -> None:
    """Set the name ``ps -o comm``, ``top`` and ``pgrep NAME`` show (Linux; 15 bytes at most,
    longer names are cut); no-op elsewhere."""
    _prctl(PR_SET_NAME, name.encode()[:15])


def die_with_parent() -> None:
    """Ask Linux to send SIGTERM when the parent process dies (no orphans); no-op elsewhere."""
    import signal

    if sys.platform.startswith("linux"):
        _prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
        parent = os.environ.get(PARENT_PID_VARIABLE)
        if parent is not None and parent.isdigit() and os.getppid() != int(parent):
            os.kill(os.getpid(), signal.SIGTERM)  # the parent died before prctl took effect
