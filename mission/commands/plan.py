"""``mission plan``: the support UAVs' paths planned and written as waypoint files."""

from __future__ import annotations

import argparse
from pathlib import Path

from mission.commands.common import add_scenario_argument, check_figure_path
from mission.config.errors import InputError
from mission.procs.disk_full import fresh, removed_if_disk_fills
from mission.procs.outputs import check_output_dir


def add_parser(commands) -> None:
    """``mission plan``'s arguments."""
    parser = commands.add_parser("plan", help="plan the support UAVs' paths; write waypoint files")
    add_scenario_argument(parser)
    parser.add_argument(
        "--out",
        type=Path,
        metavar="DIR",
        help="directory for the files (default: the scenario's waypoints_dir)",
    )
    parser.add_argument("--plot", type=Path, metavar="FILE.png|pdf|svg", help="draw the plan")
    parser.set_defaults(handler=plan)


def plan(args: argparse.Namespace) -> int:
    """``mission plan``."""
    from mission.link.plan_files import vehicle_names, write_plan
    from mission.planning.planner import plan_supports
    from mission.planning.zone_placement import place_along, place_along_pair, place_wall
    from mission.world.model import World

    world = World.load(args.scenario)
    out = plan_directory(args.out, world.scenario)
    if args.plot is not None:
        check_figure_path(args.plot, "--plot", made=out)
    plan = plan_supports(world)
    names = vehicle_names(world.scenario.task.supports)
    outputs = [out, *(out / f"{name}.waypoints" for name in names)]
    outputs += [args.plot] if args.plot is not None else []
    with removed_if_disk_fills(*fresh(*outputs)):  # the plan and its figure, or neither
        written = write_plan(plan, world.scenario, out)
        if args.plot is not None:
            from mission.planning.plan_plot import plot_plan

            plot_plan(world, plan, args.plot)
            written.append(args.plot)
    for path in written:
        print(f"wrote {path}")
    if out.resolve() != Path(world.scenario.task.waypoints_dir).resolve():
        print(f"to fly it: task: {{waypoints_dir: {out.resolve()}}} in the scenario")
    try:
        along, segment = place_along(plan, world.workspace)
        print(
            f"an Along zone for this plan (segment w_1,{segment + 1} -> w_1,{segment + 2}): "
            f"min_m {list(along.min_m)}, max_m {list(along.max_m)}"
        )
    except ValueError as reason:
        print(f"an Along zone: {reason}")
    try:
        wall = place_wall(plan, world.workspace)
        print(
            f"a Wall zone for this plan (around w_1,6): min_m {list(wall.min_m)}, "
            f"max_m {list(wall.max_m)}"
        )
    except (ValueError, IndexError):
        print("a Wall zone: no place on this plan")
    if world.scenario.task.supports >= 2:
        try:
            pair = place_along_pair(plan, world.workspace)
            print("two Along zones for this plan (two supports in multipath at once):")
            for support, segment, zone in pair:
                print(
                    f"  support {support + 1}, segment w_{support + 1},{segment + 1} -> "
                    f"w_{support + 1},{segment + 2}: min_m {list(zone.min_m)}, "
                    f"max_m {list(zone.max_m)}"
                )
        except ValueError as reason:
            print(f"two Along zones: {reason}")
    return 0


def plan_directory(out: Path | None, scenario) -> Path:
    """Where ``mission plan`` writes: ``--out``, else the scenario's own ``waypoints_dir``
    when the scenario sets one outside the package, else ``<name>-plan/`` beside the user's
    scenario file (in the current directory for an embedded scenario). Never inside the
    installed package (its shipped plans would change every later run)."""
    package = Path(__file__).resolve().parents[1]
    if out is None:
        planned = Path(scenario.task.waypoints_dir)
        source = Path(scenario.source)
        if not planned.resolve().is_relative_to(package):
            out = planned
        elif source.resolve().is_relative_to(package):
            out = Path.cwd() / f"{scenario.name}-plan"
        else:
            out = source.parent / f"{scenario.name}-plan"
    if out.resolve().is_relative_to(package):
        raise InputError("command line", "--out", f"{out} is inside the installed package")
    check_output_dir(out, "--out")
    return out
