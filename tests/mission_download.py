"""Reading a vehicle's mission back, as a ground station could: the mission protocol's
download (MISSION_REQUEST_LIST, a MISSION_REQUEST_INT per item, then an ACK) and each item as
a waypoint file's row. The ground station only uploads; the tests download to see what the
vehicle stored."""

from __future__ import annotations

from typing import Any

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from ground_station.links.mission_client import MissionClient, MissionTransferError
from mission.link.mission_items import (
    COMMON_FIELDS,
    MISSION,
    MissionItem,
    from_int_field,
)
from mission.link.waypoints import WaypointRow

FLOAT32_FIELDS = ("param1", "param2", "param3", "param4", "z")  # float on the wire


class DownloadingClient(MissionClient):
    """The ground station's mission client, able to fetch the vehicle's mission too."""

    def download(self) -> list[MissionItem]:
        """Fetch the vehicle's mission."""
        reply = self._exchange(
            mavlink2.MAVLink_mission_request_list_message(self.system_id, 1, MISSION),
            {"MISSION_COUNT"},
        )
        items = []
        for seq in range(int(reply.count)):
            item = self._exchange(
                mavlink2.MAVLink_mission_request_int_message(self.system_id, 1, seq, MISSION),
                {"MISSION_ITEM_INT"},
                seq=seq,
            )
            items.append(MissionItem.from_message(item))
        self._send(
            mavlink2.MAVLink_mission_ack_message(
                self.system_id, 1, mavlink2.MAV_MISSION_ACCEPTED, MISSION
            )
        )
        return items

    def _exchange(self, request: Any, wanted: set[str], seq: int | None = None) -> Any:
        for _ in range(self.retries + 1):
            self._send(request)
            reply = self._wait(wanted | {"MISSION_ACK"}, seq)
            if reply is None:
                continue
            if reply.get_type() == "MISSION_ACK":
                raise MissionTransferError(
                    f"system {self.system_id} refused the download (result {reply.type})"
                )
            return reply
        raise MissionTransferError(f"system {self.system_id}: download timed out")


def float32_decimal(value: float) -> float:
    """The shortest decimal that a float32 field value came from (20.123, not 20.1229991...)."""
    return float(str(np.float32(value)))


def row_from_item(item: MissionItem) -> WaypointRow:
    """A downloaded item as a waypoint file's row; float32 fields become the decimals they
    were written as."""
    common = {name: getattr(item, name) for name, _ in COMMON_FIELDS}
    common.update((name, float32_decimal(common[name])) for name in FLOAT32_FIELDS)
    x, y = from_int_field(item.x, item.frame), from_int_field(item.y, item.frame)
    return WaypointRow(**common, x=x, y=y)
