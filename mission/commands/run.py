"""``mission run``: a mission flown, its vehicle processes and ground station started and
stopped together."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from mission.analysis.lockstep import integrity_note
from mission.commands.common import (
    add_realtime_arguments,
    add_scenario_argument,
    realtime_speedup,
)
from mission.config.errors import InputError
from mission.config.run_outputs import G_SNAPSHOTS
from mission.link.impairment import add_link_arguments, link_settings
from mission.procs.command_line import check_seed
from mission.procs.outputs import check_output_dir, run_files_in
from mission.runs.stall import DEFAULT_STALL_S


def add_parser(commands) -> None:
    """``mission run``'s arguments."""
    parser = commands.add_parser("run", help="run a mission: vehicle processes + ground station")
    add_scenario_argument(parser)
    parser.add_argument(
        "--method",
        choices=["ac", "nac"],
        default="ac",
        help="ac: adaptive control (G learned); nac: the baseline without the update",
    )
    parser.add_argument("--seed", type=int, default=0, help="seed of every random draw of the run")
    parser.add_argument(
        "--out", type=Path, metavar="DIR", help="default logs/<scenario>-<method>-<seed>-<time>/"
    )
    add_realtime_arguments(parser, "the run")
    parser.add_argument(
        "--signing-key", type=Path, metavar="FILE", help="sign every link (32-byte secret)"
    )
    parser.add_argument(
        "--observer",
        metavar="HOST:PORT",
        help="every vehicle also streams here (QGroundControl, MAVProxy); use with --realtime",
    )
    add_link_arguments(parser)
    parser.add_argument(
        "--mpc-helper",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="the ground station shares the support MPCs with a helper process "
        "(default: with two or more cores; same results either way)",
    )
    parser.add_argument(
        "--g-snapshots",
        choices=G_SNAPSHOTS,
        default="every",
        help="which snapshots of G the run keeps in OUT/g: every (the start, every 20 cycles "
        "and the end: what the 3-D view replays; the default), ends (the start and the end: "
        "what G learned), none (a lean run, as a study's that keeps no g/)",
    )
    parser.add_argument(
        "--stall-s",
        type=float,
        default=DEFAULT_STALL_S,
        metavar="S",
        help="stop the run, as failed and with its logs, when its tlog has not grown for S "
        f"seconds of wall time (a hung solver or wait; default {DEFAULT_STALL_S:g}, 0: never)",
    )
    parser.add_argument(
        "--process-start",
        choices=["fork", "exec"],
        default="fork",
        help="fork: the ground station and the vehicles are forked from this process, the "
        "vehicles after one import of their code (exec where forking is unsafe); exec: each is "
        "started as python -m ground_station / vehicle_sim (slower; ps shows its command "
        "line). Same results either way",
    )
    parser.add_argument(
        "--view",
        nargs="?",
        const="auto",
        choices=["auto", "web", "native"],
        help="stream the run to a Rerun viewer (auto: native with a display, else web)",
    )
    parser.add_argument(
        "--force",
        action="store_true",
        help="write over an earlier run in OUT (its files are removed first); without it, a "
        "folder holding a run is refused",
    )
    parser.add_argument("--exit-with-parent", action="store_true", help=argparse.SUPPRESS)
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    """``mission run``: the flags checked (each named as given), then the run prepared and
    flown by the Python API (:mod:`mission.api.runner`), as ``mission.run`` flies it."""
    from mission.api.runner import announce, clear, fly, prepare
    from mission.procs.command_line import EXIT_NOT_COMPLETED
    from mission.runs.orchestrator import RunFailed

    if args.exit_with_parent:
        from mission.procs.process_life import die_with_parent

        die_with_parent()
    check_seed(args.seed)
    speedup = realtime_speedup(args)
    _check_flags(args)
    plan = prepare(
        args.scenario,
        args.method,
        args.seed,
        None,
        args.out,
        speedup=speedup,
        force=args.force,
        signing_key=args.signing_key,
        observer=args.observer,
        link=link_settings(args),
        mpc_helper=args.mpc_helper,
        process_start=args.process_start,
        g_snapshots=args.g_snapshots,
        stall_s=args.stall_s,
    )
    out, live = plan.out, None
    clear(plan)  # --force: the earlier run's files, once every check has passed
    print(announce(plan), flush=True)
    try:
        live = _live_view(args.view, out, plan.scenario) if args.view else None
        summary = fly(plan, live)
        status = 0 if summary["completed"] else EXIT_NOT_COMPLETED
        timeout_s = plan.scenario.run.timeout_s
        print(f"{run_line(summary, timeout_s)}; summary in {out / 'summary.json'}")
        if live is not None and live.viewer is not None:
            from mission.viewer.replay import wait_for_viewer

            wait_for_viewer(live.viewer)
    except RunFailed as error:
        print(f"run failed: {error}; logs kept in {out}", file=sys.stderr)
        return 1
    finally:
        if live is not None:
            live.close()
    return status


def _check_flags(args: argparse.Namespace) -> None:
    """The flags that name files, folders and addresses, each checked before anything
    starts and named as given."""
    if not (0 <= args.stall_s < float("inf")):
        problem = f"must be finite and >= 0, not {args.stall_s}"
        raise InputError("command line", "--stall-s", problem)
    if args.signing_key is not None:
        from mission.link.signing import read_signing_key

        read_signing_key(args.signing_key)  # a bad key fails here, before anything starts
    if args.observer is not None:
        from mission.link.mavlink_udp import parse_address

        try:
            parse_address(args.observer)
        except ValueError as error:
            raise InputError("command line", "--observer", str(error)) from None
    if args.out is not None:
        check_output_dir(args.out, "--out")
        earlier = run_files_in(args.out)
        if earlier and not args.force:
            raise InputError(
                "command line",
                "--out",
                f"{str(args.out)!r} holds a run ({earlier[0].name}): give a new folder, or "
                "--force to write over it",
            )


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


def run_line(summary: dict, timeout_s: float) -> str:
    """A finished run in one line of text."""
    if summary["completed"]:
        roles = summary.get("roles") or {}
        reached = roles.get("waypoints_reached") or {}
        behind = [n for n, w in reached.items() if n != "work" and w["reached"] < w["of"]]
        inspected = any(n != "work" for n in reached)
        work = "work task " if inspected else ""
        done = f"{work}completed at {summary['completion_time_s']:.1f} s"
        if behind:  # the work UAV's task done, a support's inspections not
            done += f", inspections NOT done within {timeout_s:g} s ({', '.join(behind)})"
        elif inspected and roles.get("all_done_s") is not None:
            done += f", every inspection done at {roles['all_done_s']:.1f} s"
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
        f"wall {summary['wall_time_s']:.1f} s{speed}{closest}{clear}{integrity_note(summary)}"
    )
