"""A small ground-station-side MAVLink client for tests, built on the project's UDP endpoint."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.link.mavlink_udp import Address, MavlinkCodec, MessageQueue, UdpEndpoint
from mission.world.frames import GeodeticFrame, enu_to_ned

GCS_SYSTEM_ID = 255
GCS_COMPONENT_ID = 190
POSITION_ONLY = 0b0000_1101_1111_1000


class MavClient:
    """Send messages to vehicles and wait for particular replies."""

    def __init__(
        self, *vehicles: Address, system_id: int = GCS_SYSTEM_ID, signing_key: bytes | None = None
    ) -> None:
        self.vehicles = list(vehicles)
        self.vehicle = self.vehicles[0]
        self.endpoint = UdpEndpoint(MavlinkCodec(system_id, GCS_COMPONENT_ID, signing_key))
        self.queue = MessageQueue(self.endpoint)
        self.seen: list[Any] = []

    def send(self, message: Any, to: Address | None = None) -> None:
        """Send to one vehicle (default: the first)."""
        self.endpoint.send(message, [to or self.vehicle])

    def wait_for(
        self, kind: str, timeout_s: float = 5.0, where: Callable[[Any], bool] | None = None
    ) -> Any | None:
        """The next message of this type (matching ``where``), or None after the timeout."""
        deadline = time.monotonic() + timeout_s
        while (got := self.queue.next(deadline - time.monotonic())) is not None:
            message = got[0]
            self.seen.append(message)
            if message.get_type() == kind and (where is None or where(message)):
                return message
        return None

    def collect(self, duration_s: float) -> list[Any]:
        """Everything that arrives within ``duration_s``."""
        got: list[Any] = []
        deadline = time.monotonic() + duration_s
        while (item := self.queue.next(deadline - time.monotonic())) is not None:
            got.append(item[0])
        self.seen.extend(got)
        return got

    def command(
        self,
        command: int,
        *params: float,
        to: Address | None = None,
        system_id: int = 1,
        timeout_s: float = 3.0,
    ) -> int | None:
        """COMMAND_LONG; the COMMAND_ACK result or None (none within ``timeout_s``)."""
        values = [*params, *[0.0] * (7 - len(params))]
        self.send(mavlink2.MAVLink_command_long_message(system_id, 1, command, 0, *values), to)
        ack = self.wait_for("COMMAND_ACK", timeout_s, where=lambda m: m.command == command)
        return None if ack is None else int(ack.result)

    def arm_guided(self, system_id: int, to: Address | None = None) -> None:
        """GUIDED mode and armed, both acknowledged."""
        mode = self.command(mavlink2.MAV_CMD_DO_SET_MODE, 1, 4, to=to, system_id=system_id)
        arm = self.command(mavlink2.MAV_CMD_COMPONENT_ARM_DISARM, 1, to=to, system_id=system_id)
        assert mode == arm == mavlink2.MAV_RESULT_ACCEPTED

    def setpoint(
        self,
        system_id: int,
        target_enu: np.ndarray,
        to: Address | None = None,
        type_mask: int = POSITION_ONLY,
        frame: int = mavlink2.MAV_FRAME_LOCAL_NED,
        time_boot_ms: int = 0,
    ) -> None:
        """SET_POSITION_TARGET_LOCAL_NED toward an ENU point (stamped ``time_boot_ms``; 0:
        unstamped)."""
        n, e, d = (float(v) for v in enu_to_ned(target_enu))
        self.send(
            mavlink2.MAVLink_set_position_target_local_ned_message(
                time_boot_ms, system_id, 1, frame, type_mask, n, e, d, 0, 0, 0, 0, 0, 0, 0, 0
            ),
            to,
        )

    def estimate(self, position_enu: np.ndarray, to: Address | None = None, usec: int = 0) -> None:
        """VISION_POSITION_ESTIMATE of an ENU position (stamped ``usec``; 0: unstamped)."""
        n, e, d = (float(v) for v in enu_to_ned(position_enu))
        self.send(mavlink2.MAVLink_vision_position_estimate_message(usec, n, e, d, 0, 0, 0), to)

    def step_to(self, time_ms: int, timeout_s: float = 5.0) -> list[Any]:
        """Lockstep: tick every vehicle to ``time_ms`` and return what they sent for that step."""
        tick = mavlink2.MAVLink_system_time_message(0, time_ms)
        for vehicle in self.vehicles:
            self.send(tick, vehicle)
        waiting = len(self.vehicles)
        got: list[Any] = []
        deadline = time.monotonic() + timeout_s
        while waiting and (item := self.queue.next(deadline - time.monotonic())) is not None:
            message = item[0]
            got.append(message)
            if message.get_type() == "SYSTEM_TIME" and message.time_boot_ms == time_ms:
                waiting -= 1
        assert waiting == 0, f"vehicles did not finish the step to {time_ms} ms"
        self.seen.extend(got)
        return got

    def close(self) -> None:
        """Close the socket."""
        self.endpoint.close()


def truth_of(sim_state: Any, frame: GeodeticFrame) -> np.ndarray:
    """ENU truth from SIM_STATE (lat_int/lon_int, alt)."""
    return frame.from_degE7(sim_state.lat_int, sim_state.lon_int, sim_state.alt)


def last(messages: list[Any], kind: str, system_id: int | None = None) -> Any:
    """The last message of a type (from a system) in a list."""
    found = [
        m
        for m in messages
        if m.get_type() == kind and (system_id is None or m.get_srcSystem() == system_id)
    ]
    assert found, f"no {kind}"
    return found[-1]
