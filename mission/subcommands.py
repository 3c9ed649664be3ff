"""What each ``python -m mission`` sub-command does, given its parsed arguments (the parsers
are in :mod:`mission.cli`). Heavy imports happen inside each, so ``--help`` and bad arguments
answer at once."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from mission.config.errors import InputError
from mission.link.impairment import link_settings
from mission.procs.cli_common import check_seed, check_speedup, parse_point
from mission.procs.outputs import check_output_dir, check_output_file

DEFAULT_PLOT_POINT = (0.0, -7.0, 7.0)


def world(args: argparse.Namespace) -> int:
    """``mission world``."""
    point = parse_point(args.at, "--at") if args.at is not None else None
    from mission.world.model import World

    if args.plot is not None:
        _check_output_path(args.plot, "--plot")
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
    return 0


def run(args: argparse.Namespace) -> int:
    """``mission run``."""
    import time

    from mission.config.scenario import load_scenario
    from mission.runs.orchestrator import RunFailed, RunOptions, run_mission

    if args.exit_with_parent:
        from mission.procs.cli_common import die_with_parent

        die_with_parent()
    check_seed(args.seed)
    speedup = realtime_speedup(args)
    scenario = load_scenario(args.scenario)
    preflight(scenario)
    stamp = time.strftime("%Y%m%d-%H%M%S")
    out = args.out or Path("logs") / f"{scenario.name}-{args.method}-{args.seed}-{stamp}"
    check_output_dir(out, "--out")
    if args.signing_key is not None:
        from mission.link.signing import read_signing_key

        read_signing_key(args.signing_key)  # a bad key fails here, before anything starts
    if args.observer is not None:
        from mission.link.mavlink_udp import parse_address

        try:
            parse_address(args.observer, "--observer")
        except ValueError as error:
            raise InputError("command line", "--observer", str(error)) from None
    link = link_settings(args)
    options = RunOptions(
        args.scenario,
        args.method,
        args.seed,
        out,
        speedup,
        args.signing_key.resolve() if args.signing_key else None,
        args.observer,
        link,
        args.mpc_helper,
        args.process_start,
    )
    print(f"running {scenario.name} ({args.method}, seed {args.seed}) into {out}", flush=True)
    live = None
    try:
        live = _live_view(args.view, out, scenario) if args.view else None
        summary = run_mission(options, scenario, live)
        print(f"{run_line(summary, scenario.run.timeout_s)}; summary in {out / 'summary.json'}")
        if live is not None and live.viewer is not None:
            from mission.viewer.replay import wait_for_viewer

            wait_for_viewer(live.viewer)
    except RunFailed as error:
        print(f"run failed: {error}; logs kept in {out}", file=sys.stderr)
        return 1
    finally:
        if live is not None:
            live.close()
    return 0


def _live_view(choice: str, out: Path, scenario):
    """The live view of ``mission run --view``: its viewer started (and its URL said)."""
    from mission.runs.orchestrator import RunFailed
    from mission.viewer.live import LiveView
    from mission.viewer.process import ViewerFailed, start_viewer
    from mission.viewer.replay import viewer_kind

    kind = "native" if choice == "native" else viewer_kind(choice == "web")
    out.mkdir(parents=True, exist_ok=True)
    try:
        viewer = start_viewer(kind, out / "viewer.log")
    except ViewerFailed as error:
        raise RunFailed(f"the viewer: {error}") from None
    print(f"streaming to the viewer at {viewer.web_url or 'its native window'}", flush=True)
    return LiveView(out, scenario, viewer)


def realtime_speedup(args: argparse.Namespace) -> float | None:
    """The real-time speed-up (None: lockstep); --speedup only with --realtime."""
    if not args.realtime:
        if args.speedup is not None:
            raise InputError("command line", "--speedup", "is for --realtime runs (add --realtime)")
        return None
    speedup = 1.0 if args.speedup is None else args.speedup
    check_speedup(speedup)
    if args.speedup is None:
        print(
            "real time at 1x: a run takes as long as its flight (minutes); "
            "--speedup X runs X times faster",
            file=sys.stderr,
        )
    return speedup


def run_line(summary: dict, timeout_s: float) -> str:
    """A finished run in one line of text."""
    if summary["completed"]:
        done = f"completed at {summary['completion_time_s']:.1f} s"
    elif summary.get("stopped"):
        done = f"STOPPED: {summary['stopped']}"
    else:
        done = f"NOT completed within {timeout_s:g} s"
    safety = summary.get("safety") or {}
    approaches = list((safety.get("closest_approach_m") or {}).values())
    clearances = list((safety.get("least_clearance_m") or {}).values())
    closest = f"; closest approach {min(approaches):.2f} m" if approaches else ""
    clear = f", least clearance {min(clearances):.2f} m" if clearances else ""
    per_support = ", ".join(f"{name} {n}" for name, n in summary["multipath_steps"].items())
    mean = summary["work_error_m"]["mean"]
    error = "no estimate" if mean is None else f"mean {mean:.4f} m"
    factor = summary["realtime_factor"]
    speed = "" if factor is None else f", {factor:.0f}x real time"
    return (
        f"{done}; {summary['control_cycles']} cycles; steps in multipath "
        f"{summary['multipath_steps_total']} ({per_support}); work UAV error {error}; "
        f"wall {summary['wall_time_s']:.1f} s{speed}{closest}{clear}"
    )


def preflight(scenario) -> None:
    """Everything a run reads from files, checked before any process starts: the structure's
    mesh (loading the known world) and every vehicle's waypoint file."""
    from mission.link.plan_check import check_plan_files
    from mission.link.plan_files import vehicle_names
    from mission.world.model import KnownWorld

    world = KnownWorld(scenario)
    names = vehicle_names(scenario.task.supports)
    check_plan_files(world, Path(scenario.task.waypoints_dir), names)


def plan(args: argparse.Namespace) -> int:
    """``mission plan``."""
    from mission.link.plan_files import write_plan
    from mission.planning.planner import plan_supports
    from mission.planning.zone_placement import place_along, place_along_pair, place_wall
    from mission.world.model import World

    world = World.load(args.scenario)
    out = plan_directory(args.out, world.scenario)
    if args.plot is not None:
        _check_output_path(args.plot, "--plot", made=out)
    plan = plan_supports(world)
    for path in write_plan(plan, world.scenario, out):
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
    if args.plot is not None:
        from mission.planning.plan_plot import plot_plan

        plot_plan(world, plan, args.plot)
        print(f"wrote {args.plot}")
    return 0


def plan_directory(out: Path | None, scenario) -> Path:
    """Where ``mission plan`` writes: ``--out``, else the scenario's own ``waypoints_dir``
    when the scenario sets one outside the package, else ``<name>-plan/`` beside the user's
    scenario file (in the current directory for an embedded scenario). Never inside the
    installed package (its shipped plans would change every later run)."""
    package = Path(__file__).resolve().parent
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


def bench(args: argparse.Namespace) -> int:
    """``mission bench``."""
    from mission.runs.bench import format_table, run_benchmarks

    results = run_benchmarks(args.only)
    if args.json:
        print(json.dumps({r.name: r.value for r in results}))
    else:
        print(format_table(results))
    return 0


def _check_output_path(path: Path, flag: str, made: Path | None = None) -> None:
    """A figure's path; its folder may be ``made`` (checked as a folder this command makes)."""
    from mission.analysis.figures import FIGURE_SUFFIXES

    if made is not None and Path(path).parent.resolve() == Path(made).resolve():
        check_output_dir(made, flag)
        if Path(path).is_dir() or Path(path).suffix.lower() not in FIGURE_SUFFIXES:
            check_output_file(path, flag, FIGURE_SUFFIXES)  # says which
        return
    check_output_file(path, flag, FIGURE_SUFFIXES)
