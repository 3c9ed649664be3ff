"""Entry point for ``python -m mission`` and the ``mission`` command."""

import sys

from mission.procs.numerics import prepare_numerics


def main() -> int:
    """Set up the numerics, then run the command line."""
    prepare_numerics()  # before anything imports numpy
    # numpy loads with the set-up; `mission run` forks its vehicles, which keep it
    from mission.cli import entry_point

    return entry_point()


if __name__ == "__main__":
    sys.exit(main())
