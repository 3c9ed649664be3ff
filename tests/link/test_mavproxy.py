"""MAVProxy, a real ground station from PyPI, loads and lists a mission on our vehicle."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from ground_station.links.mission_client import MissionTransferError
from mission.link.waypoints import (
    WaypointRow,
    format_waypoints,
    read_waypoints,
    waypoint_rows_from_enu,
    write_waypoints,
)
from mission.world.frames import GeodeticFrame
from tests.mav_client import MavClient
from tests.mission_download import DownloadingClient, row_from_item
from tests.processes import stop_process, vehicle_process

pytestmark = pytest.mark.slow  # every test here starts processes
RECEIVED = re.compile(r"Received \d+ parameters")


def _mavproxy(
    port: int, command: str, cwd: Path, modules: str = "wp", commands_later: bool = False
) -> tuple[subprocess.Popen, list[str]]:
    """MAVProxy at a vehicle running ``command``; with ``commands_later`` it also reads more
    commands from its stdin (a pipe)."""
    executable = shutil.which("mavproxy.py") or str(Path(sys.executable).parent / "mavproxy.py")
    process = subprocess.Popen(
        [
            sys.executable,
            executable,
            f"--master=udpout:127.0.0.1:{port}",
            "--target-system=2",
            *([] if commands_later else ["--non-interactive"]),
            "--no-state",
            f"--default-modules={modules}",
            f"--cmd={command}",
        ],
        stdin=subprocess.PIPE if commands_later else subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        cwd=cwd,
    )
    lines: list[str] = []
    assert process.stdout is not None
    threading.Thread(target=lambda: lines.extend(process.stdout), daemon=True).start()
    return process, lines


def test_mavproxy_loads_and_lists_a_waypoint_file(along, tmp_path):
    points = np.array([[0.0, -10.0, 7.0], [3.0, -10.0, 7.0], [6.0, -11.0, 8.0]])
    path = tmp_path / "support-1.waypoints"
    write_waypoints(path, waypoint_rows_from_enu(points, GeodeticFrame(along.world.anchor), 0.1))
    with vehicle_process("support-1", "--speedup", "1") as vehicle:
        loader, _ = _mavproxy(vehicle.port, f"wp load {path}", tmp_path)
        client = MavClient(vehicle.address)
        mission = DownloadingClient(client.queue, vehicle.address, 2, timeout_s=0.5, retries=1)
        rows: list[WaypointRow] = []
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and len(rows) != 4:
            time.sleep(0.5)
            try:
                rows = [row_from_item(item) for item in mission.download()]
            except MissionTransferError:
                continue
        stop_process(loader)
        client.close()
        assert format_waypoints(rows) == path.read_text(), "the vehicle holds the file's mission"

        lister, lines = _mavproxy(vehicle.port, "wp list", tmp_path)
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and sum(line.startswith("16 3 ") for line in lines) < 4:
            time.sleep(0.2)
        stop_process(lister)
    listed = [line.split() for line in lines if line.startswith("16 3 ")]
    assert len(listed) == 4
    for fields, row in zip(listed, read_waypoints(path)):
        assert float(fields[2]) == row.x and float(fields[3]) == row.y
        assert float(fields[4]) == row.z


def _read(reader: MavClient, name: str) -> float | None:
    """A parameter's value read by id (None: no answer)."""
    reader.send(mavlink2.MAVLink_param_request_read_message(2, 1, name.encode(), -1))
    echo = reader.wait_for("PARAM_VALUE", timeout_s=0.5, where=lambda m: m.param_id == name)
    return None if echo is None else echo.param_value


def test_mavproxy_fetches_and_shows_the_parameters_after_its_ftp_attempt(tmp_path):
    """MAVProxy with its ftp module asks for ``@PARAM/param.pck`` first; the vehicle's NAK
    sends it to the parameter protocol at once, ``param show`` lists the vehicle's parameters
    with their values, and ``param set`` changes a live one and not a read-only one."""
    with vehicle_process("support-1", "--speedup", "1") as vehicle:
        shower, lines = _mavproxy(
            vehicle.port, "param fetch", tmp_path, modules="param,ftp", commands_later=True
        )
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline and not any(RECEIVED.search(x) for x in lines):
            time.sleep(0.2)
        assert shower.stdin is not None
        shower.stdin.write("param show SIM_*\nparam show WPNAV_SPEED\n")
        shower.stdin.write("param set SIM_GPS_UERE 0.5\nparam set SIM_SPEEDUP 3\n")
        shower.stdin.flush()
        while time.monotonic() < deadline and not any("WPNAV_SPEED" in x for x in lines):
            time.sleep(0.2)
        reader = MavClient(vehicle.address)
        try:  # a second ground station sees what MAVProxy's sets did
            while time.monotonic() < deadline and _read(reader, "SIM_GPS_UERE") != 0.5:
                time.sleep(0.2)
            values = {name: _read(reader, name) for name in ("SIM_GPS_UERE", "SIM_SPEEDUP")}
        finally:
            reader.close()
        stop_process(shower)
    assert values == {"SIM_GPS_UERE": 0.5, "SIM_SPEEDUP": 1.0}, (values, lines)  # 3: refused
    assert any("parameter list (ftp)" in x for x in lines), "MAVProxy tried FTP first"
    shown = {x.split()[0]: x.split()[1] for x in lines if x.startswith(("SIM_", "WPNAV_"))}
    assert float(shown["WPNAV_SPEED"]) == 100.0 and float(shown["SIM_SPEEDUP"]) == 1.0, lines


def test_mavproxy_sets_an_integer_parameter_it_has_not_fetched(tmp_path):
    """``param forceload`` at start-up, before MAVProxy has the vehicle's list, sends
    ``SIM_GPS1_ENABLE 0`` as REAL32 (pymavlink's mavset without a known type): the vehicle
    takes it, as ArduPilot does, and keeps it as the integer it declares."""
    (tmp_path / "gps-off.parm").write_text("SIM_GPS1_ENABLE 0\n")
    with vehicle_process("support-1", "--speedup", "1") as vehicle:
        setter, lines = _mavproxy(
            vehicle.port, "param forceload gps-off.parm", tmp_path, modules="param"
        )
        reader = MavClient(vehicle.address)
        try:
            deadline = time.monotonic() + 30
            while time.monotonic() < deadline and _read(reader, "SIM_GPS1_ENABLE") != 0.0:
                time.sleep(0.2)
            name = b"SIM_GPS1_ENABLE"
            reader.send(mavlink2.MAVLink_param_request_read_message(2, 1, name, -1))
            echo = reader.wait_for(
                "PARAM_VALUE", timeout_s=1.0, where=lambda m: m.param_id == name.decode()
            )
        finally:
            reader.close()
            stop_process(setter)
    assert any("set SIM_GPS1_ENABLE to 0" in x for x in lines), lines  # sent unchecked
    assert echo is not None and echo.param_value == 0.0, lines
    assert echo.param_type != mavlink2.MAV_PARAM_TYPE_REAL32  # still its declared integer
