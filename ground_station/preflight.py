"""Before the first control cycle: every vehicle heard, its waypoint file uploaded over the
mission protocol, then GUIDED and armed, each command acknowledged."""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from ground_station.links.mission_client import MissionClient, MissionTransferError
from ground_station.links.outgoing import GUIDED_AND_ARMED, gcs_heartbeat
from ground_station.links.vehicle_links import StationError, VehicleLinks, VehicleView
from mission.link.waypoints import read_waypoints, row_position_enu
from mission.world.frames import GeodeticFrame

COMMAND_TIMEOUT_WALL_S = 5.0  # a command is repeated until acknowledged, this long at most
# A mission message unanswered for this many lockstep retries is sent again: 0.2 s on a local
# link, longer with its delay (the protocol's 1.5 s made an upload over a link losing 30 % take
# a minute; MAVSDK suggests 0.5 s, less on one host), for MISSION_SILENCE_WALL_S (a vehicle that
# answers nothing for that long has stopped answering).
MISSION_REPLY_RETRIES = 10
MISSION_SILENCE_WALL_S = 10.0


def connect(links: VehicleLinks, timeout_wall_s: float) -> None:
    """Wait for every vehicle's heartbeat (announcing ourselves so they answer)."""
    beat = gcs_heartbeat()
    views = links.views.values()
    names = ", ".join(f"{v.name} {v.address[0]}:{v.address[1]}" for v in views)
    print(f"ground station waiting up to {timeout_wall_s:g} s for {names}", file=sys.stderr)
    deadline = time.monotonic() + timeout_wall_s
    while time.monotonic() < deadline:
        for view in views:
            links.send(beat, view)
        links.pump(0.5, lambda: all(v.heartbeat_wall > 0 for v in views))
        if all(v.heartbeat_wall > 0 for v in views):
            return
    missing = [v.name for v in views if v.heartbeat_wall < 0]
    raise StationError(f"no heartbeat from {', '.join(missing)}")


def upload_missions(
    links: VehicleLinks, waypoints_dir: Path, frame: GeodeticFrame, retry_wall_s: float
) -> dict[str, np.ndarray]:
    """Upload each vehicle's waypoint file; return their waypoints (ENU, home excluded)."""
    waypoints = {}
    for view in links.views.values():
        rows = read_waypoints(waypoints_dir / f"{view.name}.waypoints")
        client = MissionClient(
            links.queue,
            view.address,
            view.system_id,
            timeout_s=(timeout_s := MISSION_REPLY_RETRIES * retry_wall_s),
            retries=math.ceil(MISSION_SILENCE_WALL_S / timeout_s),
            on_other=links.receive,
        )
        client.on_sent = lambda packet: links.tlog.write(links.clock.time_usec, packet)
        try:
            result = client.upload([row.to_item() for row in rows])
        except MissionTransferError as error:
            raise StationError(f"{view.name}: {error}") from None
        if result != mavlink2.MAV_MISSION_ACCEPTED:
            raise StationError(f"{view.name} refused its mission (MAV_MISSION_RESULT {result})")
        waypoints[view.name] = np.array([row_position_enu(r, frame) for r in rows[1:]])
    return waypoints


def arm_all(links: VehicleLinks, retry_wall_s: float) -> None:
    """Every vehicle GUIDED and armed, each command acknowledged (repeated until it is)."""
    for view in links.views.values():
        for command, params in GUIDED_AND_ARMED:
            deadline = time.monotonic() + COMMAND_TIMEOUT_WALL_S
            while not _acked(view, command) and time.monotonic() < deadline:
                links.command_long(view, command, params)
                links.pump(4 * retry_wall_s, lambda v=view, c=command: _acked(v, c))
            if not _acked(view, command):
                raise StationError(f"{view.name} did not accept command {command}")
            view.latest.pop("COMMAND_ACK", None)


def _acked(view: VehicleView, command: int) -> bool:
    ack = view.latest.get("COMMAND_ACK")
    return ack is not None and ack.command == command and ack.result == 0
