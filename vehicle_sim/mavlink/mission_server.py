"""The MAVLink mission microservice, vehicle side: upload, download, clear, set-current.

Pure protocol logic: messages in, messages out through ``send``; time comes from the caller so
that timeouts work the same in lockstep and real time. A failed or cancelled upload never
touches the stored mission.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.link.mission_items import MISSION, MissionItem, check_item


@dataclass
class _Upload:
    partner: tuple[int, int]
    count: int
    items: list[MissionItem]
    deadline: float
    retries_left: int


class MissionServer:
    """Stores one mission and serves the MAVLink mission protocol for it."""

    def __init__(
        self,
        own: tuple[int, int],
        send: Callable[[Any], None],
        notify: Callable[[int, str], None],
        timeout_s: float,
        retries: int,
        capacity: int,
    ) -> None:
        self.own = own
        self._send = send
        self._notify = notify
        self.timeout_s = timeout_s
        self.retries = retries
        self.capacity = capacity
        self.items: list[MissionItem] = []
        self.current = 0
        self._upload: _Upload | None = None
        self._finished: tuple[tuple[int, int], int] | None = None  # (partner, count) last done
        self.on_changed: Callable[[], None] | None = None

    # -- dispatch ---------------------------------------------------------------------------
    def handle(self, msg: Any, now: float) -> bool:
        """Process a mission-protocol message addressed to us; True if it was one."""
        handler = self._HANDLERS.get(msg.get_type())
        if handler is None:
            return False
        handler(self, msg, now)
        return True

    def tick(self, now: float) -> None:
        """Re-request a late item, or cancel the upload when retries run out."""
        upload = self._upload
        if upload is None or now < upload.deadline:
            return
        if upload.retries_left <= 0:
            self._upload = None
            self._ack(upload.partner, mavlink2.MAV_MISSION_OPERATION_CANCELLED)
            self._notify(mavlink2.MAV_SEVERITY_WARNING, "Mission upload timed out")
            return
        upload.retries_left -= 1
        self._request(upload, now)

    # -- handlers ---------------------------------------------------------------------------
    def _on_count(self, msg: Any, now: float) -> None:
        partner = _partner(msg)
        if _mission_type(msg) != MISSION:
            self._ack(partner, mavlink2.MAV_MISSION_UNSUPPORTED, _mission_type(msg))
            return
        if msg.count > self.capacity:
            self._upload = None
            self._ack(partner, mavlink2.MAV_MISSION_NO_SPACE)
            return
        if msg.count == 0:
            self._upload = None
            self._replace([])
            self._ack(partner, mavlink2.MAV_MISSION_ACCEPTED)
            return
        self._finished = None
        self._upload = _Upload(partner, int(msg.count), [], now + self.timeout_s, self.retries)
        self._request(self._upload, now)

    def _on_item(self, msg: Any, now: float) -> None:
        partner = _partner(msg)
        upload = self._upload
        if _mission_type(msg) != MISSION:
            self._ack(partner, mavlink2.MAV_MISSION_UNSUPPORTED, _mission_type(msg))
            return
        if upload is None and self._finished == (partner, msg.seq + 1):
            self._ack(partner, mavlink2.MAV_MISSION_ACCEPTED)  # our final ACK was lost
            return
        if upload is None or upload.partner != partner:
            self._ack(partner, mavlink2.MAV_MISSION_INVALID_SEQUENCE)
            return
        expected = len(upload.items)
        if msg.seq < expected:  # a repeat after a lost request: ask again for what we need
            self._request(upload, now)
            return
        if msg.seq > expected:
            self._upload = None
            self._ack(partner, mavlink2.MAV_MISSION_INVALID_SEQUENCE)
            self._notify(
                mavlink2.MAV_SEVERITY_WARNING,
                f"Mission upload aborted: got item {msg.seq}, expected {expected}",
            )
            return
        item = MissionItem.from_message(msg)
        result = check_item(item)
        if result != mavlink2.MAV_MISSION_ACCEPTED:
            self._upload = None
            self._ack(partner, result)
            self._notify(mavlink2.MAV_SEVERITY_WARNING, f"Mission item {msg.seq} rejected")
            return
        upload.items.append(item)
        upload.retries_left = self.retries
        if len(upload.items) < upload.count:
            self._request(upload, now)
            return
        self._upload = None
        self._finished = (partner, upload.count)
        self._replace(upload.items)
        self._ack(partner, mavlink2.MAV_MISSION_ACCEPTED)
        self._notify(mavlink2.MAV_SEVERITY_INFO, f"Mission accepted: {len(self.items)} items")

    def _on_request_list(self, msg: Any, now: float) -> None:
        partner = _partner(msg)
        count = len(self.items) if _mission_type(msg) == MISSION else 0
        self._send(
            mavlink2.MAVLink_mission_count_message(
                partner[0], partner[1], count, _mission_type(msg)
            )
        )

    def _on_request(self, msg: Any, now: float) -> None:
        partner = _partner(msg)
        if _mission_type(msg) != MISSION or not 0 <= msg.seq < len(self.items):
            self._ack(partner, mavlink2.MAV_MISSION_INVALID_SEQUENCE, _mission_type(msg))
            return
        item = self.items[msg.seq]
        if msg.get_type() == "MISSION_REQUEST_INT":
            self._send(item.to_int_message(partner))
        else:
            self._send(item.to_float_message(partner))

    def _on_clear_all(self, msg: Any, now: float) -> None:
        partner = _partner(msg)
        if _mission_type(msg) not in (MISSION, mavlink2.MAV_MISSION_TYPE_ALL):
            self._ack(partner, mavlink2.MAV_MISSION_UNSUPPORTED, _mission_type(msg))
            return
        self._upload = None
        self._replace([])
        self._ack(partner, mavlink2.MAV_MISSION_ACCEPTED, _mission_type(msg))

    def _on_set_current(self, msg: Any, now: float) -> None:
        if not self.set_current(int(msg.seq)):
            self._notify(mavlink2.MAV_SEVERITY_WARNING, f"Mission item {msg.seq} does not exist")
        self.send_current()

    def _on_ack(self, msg: Any, now: float) -> None:
        """A GCS's final ACK of a download: nothing to do."""

    _HANDLERS: ClassVar[dict[str, Callable[[MissionServer, Any, float], None]]] = {
        "MISSION_COUNT": _on_count,
        "MISSION_ITEM_INT": _on_item,
        "MISSION_ITEM": _on_item,
        "MISSION_REQUEST_LIST": _on_request_list,
        "MISSION_REQUEST_INT": _on_request,
        "MISSION_REQUEST": _on_request,
        "MISSION_CLEAR_ALL": _on_clear_all,
        "MISSION_SET_CURRENT": _on_set_current,
        "MISSION_ACK": _on_ack,
    }

    # -- state ------------------------------------------------------------------------------
    def set_current(self, seq: int) -> bool:
        """Make ``seq`` current; items passed on the way forward are reported as reached."""
        if not 0 <= seq < len(self.items):
            return False
        for passed in range(self.current, seq):
            self._send(mavlink2.MAVLink_mission_item_reached_message(passed))
        self.current = seq
        return True

    def send_current(self) -> None:
        """Broadcast MISSION_CURRENT."""
        state = (
            mavlink2.MISSION_STATE_NO_MISSION if not self.items else mavlink2.MISSION_STATE_ACTIVE
        )
        self._send(
            mavlink2.MAVLink_mission_current_message(self.current, len(self.items), state, 0)
        )

    def _replace(self, items: list[MissionItem]) -> None:
        self.items = list(items)
        self.current = 0
        if self.on_changed is not None:
            self.on_changed()

    def _request(self, upload: _Upload, now: float) -> None:
        seq = len(upload.items)
        upload.deadline = now + self.timeout_s
        self._send(
            mavlink2.MAVLink_mission_request_int_message(
                upload.partner[0], upload.partner[1], seq, MISSION
            )
        )

    def _ack(self, partner: tuple[int, int], result: int, mission_type: int = MISSION) -> None:
        self._send(
            mavlink2.MAVLink_mission_ack_message(partner[0], partner[1], result, mission_type)
        )


def _partner(msg: Any) -> tuple[int, int]:
    return int(msg.get_srcSystem()), int(msg.get_srcComponent())


def _mission_type(msg: Any) -> int:
    return int(getattr(msg, "mission_type", MISSION) or 0)
