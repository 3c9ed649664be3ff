"""The mission microservice, ground-station side: upload with timeouts and retries."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.link.mavlink_udp import Address, MessageQueue
from mission.link.mission_items import MISSION, MissionItem

OnOther = Callable[[Any, Address], None]


class MissionTransferError(RuntimeError):
    """A mission transfer failed: the vehicle refused it or stopped answering."""


class MissionClient:
    """Talks the mission protocol to one vehicle through a shared endpoint."""

    def __init__(
        self,
        queue: MessageQueue,
        vehicle: Address,
        system_id: int,
        timeout_s: float = 1.5,
        retries: int = 5,
        on_other: OnOther | None = None,
    ) -> None:
        self.queue = queue
        self.endpoint = queue.endpoint
        self.vehicle = vehicle
        self.system_id = system_id
        self.timeout_s = timeout_s
        self.retries = retries
        self.on_other = on_other or (lambda message, sender: None)
        self.on_sent: Callable[[bytes], None] | None = None

    def upload(self, items: list[MissionItem]) -> int:
        """Send ``items``; return the vehicle's MAV_MISSION_RESULT (raise if it stops answering)."""
        count = mavlink2.MAVLink_mission_count_message(self.system_id, 1, len(items), MISSION)
        last_sent: Any = count
        self._send(count)
        retries = self.retries
        while True:
            reply = self._wait({"MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_ACK"})
            if reply is None:
                if retries == 0:
                    raise MissionTransferError(f"system {self.system_id}: upload timed out")
                retries -= 1
                self._send(last_sent)
                continue
            retries = self.retries
            if reply.get_type() == "MISSION_ACK":
                return int(reply.type)
            if not 0 <= reply.seq < len(items):
                raise MissionTransferError(f"system {self.system_id} requested item {reply.seq}")
            item = items[reply.seq]
            last_sent = item.to_int_message((self.system_id, 1))
            self._send(last_sent)

    def _send(self, message: Any) -> None:
        packet = self.endpoint.send(message, [self.vehicle])
        if self.on_sent is not None:
            self.on_sent(packet)

    def _wait(self, wanted: set[str], seq: int | None = None) -> Any | None:
        own = self.endpoint.codec.system_id
        deadline = time.monotonic() + self.timeout_s
        while (got := self.queue.next(deadline - time.monotonic())) is not None:
            message, sender = got
            if (
                sender == self.vehicle
                and message.get_srcSystem() == self.system_id
                and message.get_type() in wanted
                and getattr(message, "target_system", own) == own
                and (seq is None or getattr(message, "seq", seq) == seq)
            ):
                return message
            self.on_other(message, sender)
        return None
