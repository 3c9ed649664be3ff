"""Start a child process by forking this one: the child calls a function of this program
instead of starting a new interpreter, so it skips Python's start-up and every import this
process has already made.

``mission run`` starts the ground station and, once it has imported their code, the four
vehicles this way, and the ground station its MPC helper: the imports of numpy, pymavlink and
the simulator (~0.25 s of CPU each) are made once, not six times, on a machine whose two cores
the processes of a run share while they set up. A forked child is a process like any other
(its own pid, sockets and log; signals and exit statuses as with ``subprocess.Popen``); only
its command line is its parent's.

A fork copies just the calling thread, so a lock another thread holds (in malloc, a logging
handler, a BLAS pool) would stay held in the child: :func:`fork_is_safe` allows it only while
this process has one thread.
"""

from __future__ import annotations

import contextlib
import gc
import os
import select
import signal
import subprocess
import sys
import time
import traceback
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

POLL_S = 0.005  # how often wait() looks at a child that has not exited


def fork_is_safe() -> bool:
    """Whether this process may fork a child that goes on running Python: Linux (its
    ``/proc`` shows the threads) and a single thread."""
    if not hasattr(os, "fork"):
        return False
    try:
        return len(os.listdir("/proc/self/task")) == 1
    except OSError:
        return False


class ForkedProcess:
    """A forked child, driven like the ``subprocess.Popen`` it stands in for."""

    def __init__(self, pid: int) -> None:
        self.pid = pid
        self.returncode: int | None = None
        self.cpu_s: float | None = None  # user + system CPU of it and its waited-for children
        self._pidfd: int | None = None  # readable once the child has exited (Linux 5.3+)
        self._pidfd_tried = False

    def poll(self) -> int | None:
        """The exit status (negative: the signal that ended it), or None while it runs."""
        if self.returncode is None:
            pid, status, usage = os.wait4(self.pid, os.WNOHANG)
            if pid == self.pid:
                self.returncode = os.waitstatus_to_exitcode(status)
                self.cpu_s = usage.ru_utime + usage.ru_stime
                if self._pidfd is not None:
                    os.close(self._pidfd)
                    self._pidfd = None
        return self.returncode

    def wait(self, timeout: float | None = None) -> int:
        """Wait for the exit status; ``subprocess.TimeoutExpired`` after ``timeout`` s. The
        wait sleeps on a pidfd where there is one (no polling: a supervisor waking every
        few ms would take CPU from the run it supervises), else polls every POLL_S."""
        deadline = None if timeout is None else time.monotonic() + timeout
        while (code := self.poll()) is None:
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                raise subprocess.TimeoutExpired(f"forked child {self.pid}", timeout or 0.0)
            descriptor = self._exit_descriptor()
            if descriptor is None:
                time.sleep(POLL_S if left is None else min(POLL_S, left))
            else:
                select.select([descriptor], [], [], left)
        return code

    def _exit_descriptor(self) -> int | None:
        if not self._pidfd_tried and hasattr(os, "pidfd_open"):
            self._pidfd_tried = True
            with contextlib.suppress(OSError):  # an older kernel: poll instead
                self._pidfd = os.pidfd_open(self.pid)
        return self._pidfd

    def send_signal(self, number: int) -> None:
        """Signal the child unless it has been waited for (its pid may be reused)."""
        if self.poll() is None:
            os.kill(self.pid, number)

    def terminate(self) -> None:
        """SIGTERM."""
        self.send_signal(signal.SIGTERM)

    def kill(self) -> None:
        """SIGKILL."""
        self.send_signal(signal.SIGKILL)


def start_forked(
    main: Callable[[list[str]], int | None],
    argv: Sequence[str],
    log: Path | None,
    keep_fds: Sequence[int] = (),
    environment: Mapping[str, str] | None = None,
) -> ForkedProcess:
    """Fork a child that runs ``main(argv)`` and exits with its status.

    Its stdout and stderr go to ``log`` (created or truncated; None: they stay this
    process's), stdin reads /dev/null, and of this process's other descriptors it keeps only
    ``keep_fds``; signal dispositions are Python's defaults again and ``environment`` is
    merged into its ``os.environ``. Call it only when :func:`fork_is_safe`.
    """
    descriptor = None if log is None else os.open(log, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
    for stream in (sys.stdout, sys.stderr):  # or the child would write them out again
        if stream is not None:
            stream.flush()
    pid = os.fork()
    if pid == 0:  # pragma: no cover (the child's coverage is not collected)
        _child(main, list(argv), descriptor, keep_fds, environment or {})
    if descriptor is not None:
        os.close(descriptor)
    return ForkedProcess(pid)


def _child(
    main: Callable[[list[str]], int | None],
    argv: list[str],
    log_descriptor: int | None,
    keep_fds: Sequence[int],
    environment: Mapping[str, str],
) -> None:
    """The forked side: set up, run, and leave through ``os._exit`` whatever happens (never
    through the parent's stack, ``finally`` blocks or exit handlers)."""
    status = 1
    try:
        # Everything inherited stays out of the collector: a parent's object freed here could
        # close a descriptor number the child has since reused.
        gc.freeze()
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        signal.set_wakeup_fd(-1)
        if log_descriptor is not None:
            os.dup2(log_descriptor, 1)
            os.dup2(log_descriptor, 2)
        null = os.open(os.devnull, os.O_RDONLY)
        os.dup2(null, 0)
        keep = {0, 1, 2, *keep_fds}
        for name in os.listdir("/proc/self/fd"):
            if int(name) not in keep:
                with contextlib.suppress(OSError):  # the listing's own, closed already
                    os.close(int(name))
        # as a fresh interpreter writing to a file would: stdout in blocks, stderr by lines
        sys.stdin = open(0, encoding="utf-8", closefd=False)  # noqa: SIM115
        sys.stdout = open(1, "w", encoding="utf-8", closefd=False)  # noqa: SIM115
        sys.stderr = open(2, "w", encoding="utf-8", buffering=1, closefd=False)  # noqa: SIM115
        os.environ.update(environment)
        result = main(argv)
        status = result if isinstance(result, int) else 0
    except SystemExit as stop:
        status = stop.code if isinstance(stop.code, int) else (0 if stop.code is None else 1)
    except KeyboardInterrupt:
        status = 128 + signal.SIGINT
    except BaseException:
        traceback.print_exc()
    finally:
        try:
            sys.stdout.flush()
            sys.stderr.flush()
        finally:
            os._exit(status)
