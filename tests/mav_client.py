"""A small ground-station-side MAVLink client for tests, built on the project's UDP endpoint."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from mission.mavlink_udp import Address, MavlinkCodec, MessageQueue, UdpEndpoint

GCS_SYSTEM_ID = 255
GCS_COMPONENT_ID = 190


class MavClient:
    """Send messages to one vehicle and wait for particular replies."""

    def __init__(self, vehicle: Address, system_id: int = GCS_SYSTEM_ID) -> None:
        self.vehicle = vehicle
        self.endpoint = UdpEndpoint(MavlinkCodec(system_id, GCS_COMPONENT_ID))
        self.queue = MessageQueue(self.endpoint)
        self.seen: list[Any] = []

    def send(self, message: Any) -> None:
        """Send to the vehicle."""
        self.endpoint.send(message, [self.vehicle])

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

    def close(self) -> None:
        """Close the socket."""
        self.endpoint.close()
