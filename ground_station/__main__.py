"""Entry point for ``python -m ground_station`` and the ``mission-ground-station`` command."""

import sys

from mission.procs.numerics import prepare_numerics


def main() -> int:
    """Set up the numerics, then run the command line."""
    prepare_numerics()  # before anything imports numpy
    from ground_station.cli import entry_point  # numpy loads here, after the set-up

    return entry_point()


if __name__ == "__main__":
    sys.exit(main())
