"""Entry point for ``python -m vehicle_sim`` and the ``mission-vehicle`` command."""

import sys

from mission.procs.numerics import prepare_numerics


def main() -> int:
    """Set up the numerics, then run the command line."""
    prepare_numerics()  # before anything imports numpy
    from vehicle_sim.cli import entry_point  # numpy loads here, after the set-up

    return entry_point()


if __name__ == "__main__":
    sys.exit(main())
