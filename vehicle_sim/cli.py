"""``python -m vehicle_sim``: start one simulated UAV."""

from __future__ import annotations

import argparse
import contextlib
import errno
import socket
import sys
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mission.config.errors import InputError
from mission.config.run_outputs import DEFAULT_SCENARIO
from mission.link.impairment import LinkSettings, add_link_arguments, link_settings
from mission.link.mavlink_udp import MavlinkCodec, UdpEndpoint, parse_address
from mission.link.plan_files import read_vehicle_waypoints
from mission.link.signing import read_signing_key
from mission.link.vehicle_identity import BASE_PORT, VehicleIdentity
from mission.procs.command_line import (
    OneLineArgumentParser,
    check_port,
    check_seed,
    check_speedup,
    parse_point,
    program_name,
    run_guarded,
)
from mission.procs.process_life import freeze_startup_heap, name_this_process
from mission.world.model import World
from vehicle_sim.process.pacing import ClockSettings
from vehicle_sim.process.signals import install_signal_handlers
from vehicle_sim.process.truth_link import TruthReceiver, TruthSender
from vehicle_sim.server import VehicleServer
from vehicle_sim.vehicle import Vehicle


def build_parser() -> OneLineArgumentParser:
    """Arguments of a vehicle process."""
    parser = OneLineArgumentParser(
        prog=program_name("vehicle_sim", "mission-vehicle"),
        description="One simulated UAV speaking MAVLink 2 over UDP.",
    )
    parser.add_argument("--scenario", default=DEFAULT_SCENARIO, help="embedded name or YAML path")
    parser.add_argument("--vehicle", required=True, help="work or support-N")
    parser.add_argument("--host", default="127.0.0.1", help="address to listen on")
    parser.add_argument(
        "--port", type=int, help=f"MAVLink UDP port (default {BASE_PORT} + instance; 0: any free)"
    )
    parser.add_argument(
        "--out",
        action="append",
        default=[],
        metavar="HOST:PORT",
        help="also stream to this address (repeatable), as SITL does for a GCS",
    )
    parser.add_argument(
        "--seed",
        type=int,
        default=0,
        help="seed of every random draw (with the vehicle's instance)",
    )
    pacing = parser.add_mutually_exclusive_group()
    pacing.add_argument(
        "--lockstep",
        action="store_true",
        help="step when the ground station's clock ticks (the default)",
    )
    pacing.add_argument("--speedup", type=float, help="real time, this many times faster")
    parser.add_argument(
        "--home",
        nargs=3,
        type=float,
        metavar=("X", "Y", "Z"),
        help="start position, ENU metres (default: first planned waypoint)",
    )
    parser.add_argument(
        "--truth-port",
        type=int,
        help="port for the other vehicles' truth (simulation only; default port + 100)",
    )
    parser.add_argument(
        "--socket-fd",
        type=int,
        metavar="FD",
        help="use this inherited, already bound UDP socket instead of --host/--port "
        "(mission run binds every socket first, so all processes start at once)",
    )
    parser.add_argument(
        "--truth-socket-fd",
        type=int,
        metavar="FD",
        help="the same for the truth port",
    )
    parser.add_argument(
        "--truth-out",
        action="append",
        default=None,
        metavar="HOST:PORT",
        help="send this vehicle's truth here (repeatable; default: every other vehicle's "
        "default truth port)",
    )
    add_link_arguments(parser)
    parser.add_argument(
        "--signing-key",
        type=Path,
        metavar="FILE",
        help="MAVLink 2 signing: 32-byte secret (raw or 64 hex digits); unsigned commands refused",
    )
    parser.add_argument(
        "--exit-with-parent",
        action="store_true",
        help="stop when the process that started this one dies",
    )
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Start the vehicle and serve until terminated."""
    args = build_parser().parse_args(argv)
    identity = _identity(args.vehicle)
    name_this_process(f"vsim-{identity.name}")  # forked by `mission run`, it has no own argv
    check_seed(args.seed)
    if args.speedup is not None:
        check_speedup(args.speedup)
    if args.socket_fd is not None and args.port is not None:
        raise InputError("command line", "--socket-fd", "cannot be combined with --port")
    port = args.port if args.port is not None else identity.default_port()
    check_port(port, "--port", allow_any=True)
    outs = [_address(text, "--out") for text in args.out]
    key = read_signing_key(args.signing_key) if args.signing_key is not None else None
    link = link_settings(args)
    world = World.load(args.scenario)
    scenario = world.scenario
    if args.home:
        home = np.array(parse_point(args.home, "--home"))
        _check_home(world, home)
    else:
        home = read_vehicle_waypoints(scenario, identity.name)[0]
    clock = ClockSettings(lockstep=args.speedup is None, speedup=args.speedup or 1.0)
    channels = _open_channels(args, identity, port, key, link, scenario.task.supports)
    server = VehicleServer(channels.endpoint, outs, clock, *channels.truth, args.exit_with_parent)
    vehicle = Vehicle(
        identity,
        scenario,
        world,
        home,
        args.seed,
        server.outbox.broadcast,
        speedup=clock.speedup,
        link_loss=link.loss,
    )
    vehicle.on_link_loss = channels.endpoint.set_loss  # SIM_LINK_LOSS, set live
    server.attach(vehicle)
    install_signal_handlers(server.stop, args.exit_with_parent)
    _print_banner(vehicle, channels, clock)
    freeze_startup_heap()
    try:
        server.run()
    finally:
        print(server.summary(), file=sys.stderr, flush=True)
        channels.close()
    return 0


@dataclass
class Channels:
    """A vehicle's sockets: its MAVLink endpoint, and the truth channel's (its sender, its
    receiver)."""

    endpoint: UdpEndpoint
    truth_sender: TruthSender | None = None
    truth_receiver: TruthReceiver | None = None

    @property
    def truth(self) -> tuple[TruthSender | None, TruthReceiver | None]:
        """(sender, receiver) of the truth channel."""
        return self.truth_sender, self.truth_receiver

    def close(self) -> None:
        """Close every socket."""
        self.endpoint.close()
        for channel in self.truth:
            if channel is not None:
                channel.close()


def _open_channels(
    args: argparse.Namespace,
    identity: VehicleIdentity,
    port: int,
    key: bytes | None,
    link: LinkSettings,
    supports: int,
) -> Channels:
    """Bind (or adopt) the vehicle's sockets."""
    base_port = port - identity.instance  # the ports of the run's vehicles count from it
    if args.truth_out is None:  # every other vehicle's truth port
        everyone = [VehicleIdentity.from_system_id(m + 1) for m in range(supports + 1)]
        others = [other for other in everyone if other != identity] if port else []
        destinations = [(args.host, other.default_truth_port(base_port)) for other in others]
    else:
        destinations = [_address(text, "--truth-out") for text in args.truth_out]
    truth_sender = TruthSender(identity.system_id, destinations)
    sock = _inherited_socket(args.socket_fd, "--socket-fd")
    with _bind_error("--port", args.host, port, defaulted=args.port is None):
        endpoint = UdpEndpoint(
            MavlinkCodec(identity.system_id, 1, key),
            (args.host, port),
            link,
            link_seed=args.seed * 1000 + identity.system_id,
            sock=sock,
        )
    channels = Channels(endpoint, truth_sender)
    truth_port = args.truth_port
    if truth_port is None:
        truth_port = identity.default_truth_port(base_port) if port else 0
    check_port(truth_port, "--truth-port", allow_any=True)
    sock = _inherited_socket(args.truth_socket_fd, "--truth-socket-fd")
    defaulted = args.truth_port is None
    with _bind_error("--truth-port", args.host, truth_port, defaulted=defaulted):
        channels.truth_receiver = TruthReceiver(
            truth_port, args.host, sock=sock, own_system=identity.system_id
        )
    return channels


@contextlib.contextmanager
def _bind_error(flag: str, host: str, port: int, defaulted: bool) -> Iterator[None]:
    """A socket that cannot bind as one line naming the flag at fault: --host for an address
    that is not this machine's, else the port's flag (busy, or not allowed)."""
    try:
        yield
    except socket.gaierror:
        raise InputError("command line", "--host", f"{host!r} is not an address") from None
    except OSError as error:
        if error.errno == errno.EADDRNOTAVAIL:
            raise InputError("command line", "--host", f"{host!r} is not this machine's") from None
        what = f"port {port} (the default)" if defaulted else f"port {port}"
        raise InputError(
            "command line", flag, f"cannot listen on {what}: {error.strerror}"
        ) from None


def _print_banner(vehicle: Vehicle, channels: Channels, clock: ClockSettings) -> None:
    """The line that says the vehicle is up, and where it listens."""
    identity = vehicle.identity
    pacing = "lockstep" if clock.lockstep else f"real time x{clock.speedup:g}"
    host, bound = channels.endpoint.address
    receiver = channels.truth_receiver
    truth = f", truth port {receiver.endpoint.address[1]}" if receiver else ""
    print(
        f"vehicle {identity.name} (sysid {identity.system_id}) listening on {host}:{bound}"
        f"{truth}, {pacing}, home {vehicle.home.round(3).tolist()}, "
        f"scenario {vehicle.scenario.name}",
        file=sys.stderr,
        flush=True,
    )


def _check_home(world: World, home: np.ndarray) -> None:
    """A start position inside the workspace and outside the structure."""
    problem = world.placement_problem(home)
    if problem is not None:
        raise InputError("command line", "--home", f"{home.tolist()} is {problem}")


def _inherited_socket(fd: int | None, flag: str) -> socket.socket | None:
    """The UDP socket open on ``fd`` (None without one); InputError if it is not one."""
    if fd is None:
        return None
    try:
        sock = socket.socket(fileno=fd)
    except OSError:
        raise InputError("command line", flag, f"{fd} is not an open socket") from None
    if (
        sock.family != socket.AF_INET
        or sock.type != socket.SOCK_DGRAM
        or sock.getsockname()[1] == 0
    ):
        sock.detach()
        raise InputError("command line", flag, f"{fd} is not a bound UDP socket")
    return sock


def _identity(name: str) -> VehicleIdentity:
    try:
        return VehicleIdentity.parse(name)
    except ValueError as error:
        raise InputError("command line", "--vehicle", str(error)) from None


def _address(text: str, flag: str):
    try:
        return parse_address(text)
    except ValueError as error:
        raise InputError("command line", flag, str(error)) from None


def entry_point(argv: Sequence[str] | None = None) -> int:
    """Run with one-line errors and exit status 2 on bad input."""
    return run_guarded(main, argv)
