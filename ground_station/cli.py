"""``python -m ground_station``: run the ground station of one mission."""

from __future__ import annotations

import argparse
import json
import os
import signal
import sys
import time
from collections.abc import Sequence
from pathlib import Path

from mission.config.errors import InputError
from mission.config.run_outputs import DEFAULT_SCENARIO, G_SNAPSHOTS
from mission.link.impairment import add_link_arguments, link_settings
from mission.link.mavlink_udp import parse_address
from mission.link.plan_check import check_plan_files
from mission.link.plan_files import vehicle_names
from mission.link.signing import read_signing_key
from mission.link.vehicle_identity import BASE_PORT, VehicleIdentity
from mission.procs.atomic import write_text_atomically
from mission.procs.command_line import (
    OneLineArgumentParser,
    check_port,
    check_seed,
    check_speedup,
    program_name,
    run_guarded,
)
from mission.procs.outputs import check_output_dir, check_output_file
from mission.procs.process_life import die_with_parent, name_this_process
from mission.procs.provenance import run_provenance
from mission.world.model import KnownWorld


def build_parser() -> OneLineArgumentParser:
    """Arguments of the ground-station process."""
    parser = OneLineArgumentParser(
        prog=program_name("ground_station", "mission-ground-station"),
        description="The ground station of one mission: fusion, the map G, the MPCs.",
    )
    parser.add_argument("--scenario", default=DEFAULT_SCENARIO, help="embedded name or YAML path")
    parser.add_argument(
        "--method",
        choices=["ac", "nac"],
        default="ac",
        help="ac: adaptive (G updated); nac: the baseline without the update",
    )
    links = parser.add_mutually_exclusive_group()
    links.add_argument(
        "--vehicles",
        metavar="work=HOST:PORT,support-1=HOST:PORT,...",
        help="where each vehicle listens",
    )
    links.add_argument(
        "--base-port",
        type=int,
        default=BASE_PORT,
        help=f"vehicles on 127.0.0.1:BASE+instance (default {BASE_PORT})",
    )
    parser.add_argument(
        "--waypoints",
        type=Path,
        metavar="DIR",
        help="the vehicles' waypoint files (default: the scenario's plan)",
    )
    parser.add_argument("--seed", type=int, default=0, help="seed of the fusion's random draws")
    parser.add_argument(
        "--out",
        type=Path,
        metavar="DIR",
        help="where gcs.tlog, records.jsonl and g/ go (default logs/gcs-TIME)",
    )
    parser.add_argument(
        "--exit-with-parent",
        action="store_true",
        help="stop when the process that started this one dies",
    )
    parser.add_argument(
        "--tlog", type=Path, metavar="FILE", help="telemetry log (default: DIR/gcs.tlog)"
    )
    parser.add_argument(
        "--speedup", type=float, help="real time, this many times faster (default: lockstep)"
    )
    add_link_arguments(parser)
    parser.add_argument(
        "--signing-key",
        type=Path,
        metavar="FILE",
        help="MAVLink 2 signing: 32-byte secret (raw or 64 hex digits)",
    )
    parser.add_argument(
        "--g-snapshots",
        choices=G_SNAPSHOTS,
        default="every",
        help="which snapshots of G to write into OUT/g: every (the start, every 20 cycles and "
        "the end; the default, what the 3-D view replays), ends (the start and the end), none",
    )
    parser.add_argument(
        "--mpc-helper",
        action=argparse.BooleanOptionalAction,
        default=(os.cpu_count() or 1) >= 2,
        help="share the support MPCs with a helper process on a second core "
        "(default: on with two or more cores; same plans either way)",
    )
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run a mission and print its summary as JSON."""
    from ground_station.links.vehicle_links import StationError
    from ground_station.station import GroundStation, StationConfig
    from ground_station.support_mpc.sharing import HelperError

    args = build_parser().parse_args(argv)
    name_this_process("ground_station")  # forked by `mission run`, it has no own argv
    if args.exit_with_parent:
        die_with_parent()
    check_seed(args.seed)
    world = KnownWorld.load(args.scenario)
    scenario = world.scenario
    if args.vehicles is None:
        check_port(args.base_port, "--base-port")
        check_port(args.base_port + scenario.task.supports, "--base-port")
    vehicles = _vehicle_addresses(args, scenario.task.supports)
    if args.speedup is not None:
        check_speedup(args.speedup)
    waypoints = args.waypoints or Path(scenario.task.waypoints_dir)
    if not waypoints.is_dir():
        raise InputError("command line", "--waypoints", f"{waypoints} is not a directory")
    check_plan_files(world, waypoints, list(vehicles))  # before anything is started
    out = args.out or Path("logs") / f"gcs-{time.strftime('%Y%m%d-%H%M%S')}"
    check_output_dir(out, "--out")
    if args.tlog is not None:
        check_output_file(args.tlog, "--tlog")
    config = StationConfig(
        adaptive=args.method == "ac",
        vehicles=vehicles,
        waypoints_dir=waypoints,
        out_dir=out,
        seed=args.seed,
        speedup=args.speedup,
        tlog_path=args.tlog,
        signing_key=read_signing_key(args.signing_key) if args.signing_key else None,
        link=link_settings(args),
        mpc_helper=args.mpc_helper,
        g_snapshots=args.g_snapshots,
    )
    station = GroundStation(world, config)
    # SIGTERM (a run stopped early) ends it as Ctrl-C does: through station.close(), which
    # waits for its MPC helper (killed at once, the helper was left a zombie for init to reap)
    signal.signal(signal.SIGTERM, _interrupted)
    host, port = station.links.endpoint.address
    print(f"ground station listening on {host}:{port}", file=sys.stderr, flush=True)
    try:
        summary = station.run()
    except (StationError, HelperError) as error:
        print(f"ground station: {error}", file=sys.stderr)
        return 1
    finally:
        station.close()
    who = {"scenario": scenario.name, "scenario_source": scenario.source}
    summary = {**who, "method": args.method, "seed": args.seed, **summary}
    summary["link"] = json.loads((out / "link.json").read_text())
    summary["provenance"] = run_provenance()
    write_text_atomically(out / "summary.json", json.dumps(summary, indent=2) + "\n")
    print(json.dumps(summary))
    return 0


def _interrupted(*_: object) -> None:
    raise KeyboardInterrupt


def _vehicle_addresses(args, supports: int) -> dict:
    if args.vehicles is None:
        return {
            name: ("127.0.0.1", VehicleIdentity.parse(name).default_port(args.base_port))
            for name in vehicle_names(supports)
        }
    vehicles = {}
    for item in args.vehicles.split(","):
        name, sep, address = item.partition("=")
        try:
            VehicleIdentity.parse(name.strip())
            vehicles[name.strip()] = parse_address(address.strip(), name)
        except ValueError as error:
            raise InputError(
                "command line",
                "--vehicles",
                str(error) if sep else f"expected NAME=HOST:PORT, got {item!r}",
            ) from None
    if "work" not in vehicles or len(vehicles) < 2:
        raise InputError("command line", "--vehicles", "needs the work UAV and a support")
    return vehicles


def entry_point(argv: Sequence[str] | None = None) -> int:
    """Run with one-line errors and exit status 2 on bad input."""
    return run_guarded(main, argv)
