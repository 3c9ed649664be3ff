"""What the project's command lines share: one-line errors, the exit statuses, argument checks."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from mission.config.errors import InputError
from mission.procs.disk_full import EXIT_NO_SPACE, no_space_error, no_space_line

EXIT_BAD_INPUT = 2
EXIT_NOT_COMPLETED = 4  # a run flown to its end whose work task did not complete
FLOWN = (0, EXIT_NOT_COMPLETED)  # ``mission run``'s statuses for a run flown to its end


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
