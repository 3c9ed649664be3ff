"""Shared pieces of the project's command-line interfaces: one-line errors, exit status 2."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from mission.config.errors import InputError
from mission.procs.disk_full import EXIT_NO_SPACE, no_space_error, no_space_line

EXIT_BAD_INPUT = 2
EXIT_NOT_COMPLETED = 4  # a run flown to its end whose work task did not complete


class DefaultsHelpFormatter(argparse.HelpFormatter):
    """Help that ends each argument's text with its default, unless the text already says
    it or there is none to say (an unset option, a flag that is off)."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        unset = action.default is None or action.default is False
        if "default" in text or unset or action.default == argparse.SUPPRESS:
            return text
        return f"{text} (default: %(default)s)"


class OneLineArgumentParser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are a single line on stderr and exit status 2, and whose
    help shows every argument's default."""

    def __init__(self, *args, **kwargs) -> None:
        kwargs.setdefault("formatter_class", DefaultsHelpFormatter)
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> None:  # type: ignore[override]
        """Report a usage error on one line and exit with status 2."""
        sys.stderr.write(f"{self.prog}: error: {message}\n")
        sys.exit(EXIT_BAD_INPUT)


def program_name(module: str, script: str) -> str:
    """How the user started this command: ``script`` (the console script) or ``python -m
    module``; for usage lines and errors."""
    return script if Path(sys.argv[0]).name == script else f"python -m {module}"


def run_guarded(main: Callable[[Sequence[str] | None], int], argv: Sequence[str] | None) -> int:
    """Run ``main``; turn bad input into one line on stderr and status 2, a full disk into
    one line and status 3 (:mod:`mission.procs.disk_full`), Ctrl-C into 130."""
    try:
        return main(argv)
    except InputError as error:
        sys.stderr.write(f"error: {error}\n")
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        sys.stderr.write("interrupted\n")
        return 130
    except OSError as error:
        full = no_space_error(error)
        if full is None:
            raise
        sys.stderr.write(no_space_line(full) + "\n")
        return EXIT_NO_SPACE


def parse_point(values: Sequence[float], flag: str) -> tuple[float, float, float]:
    """Validate a three-number point given on the command line."""
    import math

    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise InputError("command line", flag, "expects three finite numbers X Y Z")
    return float(values[0]), float(values[1]), float(values[2])


def check_seed(seed: int, flag: str = "--seed") -> None:
    """A seed is a non-negative integer (numpy's generators refuse others)."""
    if seed < 0:
        raise InputError("command line", flag, f"must not be negative, got {seed}")


# Real time from a tenth of wall speed (slower, and a vehicle's 1 Hz heartbeat takes longer
# than the ground station's connection wait) to a thousand times it.
MIN_SPEEDUP, MAX_SPEEDUP = 0.1, 1000.0


def check_speedup(speedup: float, flag: str = "--speedup") -> None:
    """A real-time speed-up in [MIN_SPEEDUP, MAX_SPEEDUP]."""
    if not MIN_SPEEDUP <= speedup <= MAX_SPEEDUP:
        raise InputError(
            "command line", flag, f"must be in [{MIN_SPEEDUP:g}, {MAX_SPEEDUP:g}], got {speedup:g}"
        )


def check_port(port: int, flag: str, allow_any: bool = False) -> None:
    """A UDP port: 1..65535 (0, any free port, where ``allow_any``)."""
    lowest = 0 if allow_any else 1
    if not lowest <= port < 65536:
        raise InputError("command line", flag, f"port must be in {lowest}..65535, got {port}")


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
