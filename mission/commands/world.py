"""``mission world``: a scenario's world in numbers (GNSS at a point, the structure, the
zones) and a figure."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from mission.commands.common import add_scenario_argument, check_figure_path
from mission.config.errors import InputError
from mission.procs.command_line import parse_point

DEFAULT_PLOT_POINT = (0.0, -7.0, 7.0)


def add_parser(commands) -> None:
    """``mission world``'s arguments."""
    parser = commands.add_parser(
        "world", help="inspect a scenario's world (GNSS, structure, zones)"
    )
    add_scenario_argument(parser)
    parser.add_argument(
        "--at",
        nargs=3,
        type=float,
        metavar=("X", "Y", "Z"),
        help="print GNSS facts at this ENU point as one JSON object",
    )
    parser.add_argument(
        "--plot",
        type=Path,
        metavar="FILE.png|pdf|svg",
        help="draw sigma_0 on top views under the deck, at the work UAV's heights and above "
        "the structure, on side and cross-section views through --at's point (default "
        f"{' '.join(f'{v:g}' for v in DEFAULT_PLOT_POINT)}), and the sky there",
    )
    parser.add_argument(
        "--multipath-map",
        type=Path,
        metavar="FILE.png|pdf|svg",
        help="draw the GNSS error reflections make on slices at the mission's heights, and "
        "the sky at the worst point (with zones, as the geometry model would make it)",
    )
    parser.set_defaults(handler=world)


def world(args: argparse.Namespace) -> int:
    """``mission world``."""
    point = parse_point(args.at, "--at") if args.at is not None else None
    from mission.world.model import World

    if args.plot is not None:
        check_figure_path(args.plot, "--plot")
    if args.multipath_map is not None:
        check_figure_path(args.multipath_map, "--multipath-map")
    world = World.load(args.scenario)
    if point is not None:
        from mission.analysis.world_report import point_report

        space = world.scenario.world.workspace
        if not all(low <= v <= high for v, low, high in zip(point, space.min_m, space.max_m)):
            where = f"{list(space.min_m)}..{list(space.max_m)}"
            raise InputError(
                "command line", "--at", f"{list(point)} is outside the workspace {where}"
            )

        print(json.dumps(point_report(world, np.array(point))))
    else:
        from mission.analysis.world_report import summary_text

        print(summary_text(world))
    if args.plot is not None:
        from mission.analysis.world_plot import plot_world

        plot_world(world, np.array(point or DEFAULT_PLOT_POINT), args.plot)
        print(f"wrote {args.plot}", file=sys.stderr if point is not None else sys.stdout)
    if args.multipath_map is not None:
        from mission.analysis.multipath_plot import plot_multipath, region_lines

        worst = plot_multipath(world, args.multipath_map)
        stream = sys.stderr if point is not None else sys.stdout
        print(
            f"wrote {args.multipath_map} (worst error {worst['worst_m']:g} m at "
            f"{worst['x']:g}, {worst['y']:g}, {worst['z']:g})",
            file=stream,
        )
        print("\n".join(region_lines(worst["regions"])), file=stream)
    return 0
