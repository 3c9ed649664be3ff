"""A mission item in each of its forms (MISSION_ITEM_INT, the float MISSION_ITEM, a waypoint
file's row) carries the same fields in the same places, with one rule for x and y: 1e-7
degrees in a global frame, the value as it is in any other."""

from __future__ import annotations

from dataclasses import replace

import pytest
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.link.mission_items import INT32_MAX, MissionItem
from tests.mission_download import row_from_item

WAYPOINT = MissionItem(
    3, mavlink2.MAV_FRAME_GLOBAL_RELATIVE_ALT, mavlink2.MAV_CMD_NAV_WAYPOINT, 0, 1,
    0.5, 2.0, 0.0, 90.0, 356123456, 1397654321, 8.5,
)  # fmt: skip
SPEED = MissionItem(  # params 5 and 6 of a command in the mission frame: not degrees
    4, mavlink2.MAV_FRAME_MISSION, mavlink2.MAV_CMD_DO_CHANGE_SPEED, 0, 1,
    1.0, 2.5, -1.0, 0.0, 5, 7, 0.0,
)  # fmt: skip


def _wire(message):
    """The message as a peer decodes it."""
    return mavlink2.MAVLink(None).decode(bytearray(message.pack(mavlink2.MAVLink(None))))


@pytest.mark.parametrize("item", [WAYPOINT, SPEED])
def test_every_form_carries_the_item_unchanged(item):
    as_int = _wire(item.to_int_message((2, 1)))
    assert (as_int.seq, as_int.frame, as_int.command, as_int.x, as_int.y) == (
        item.seq, item.frame, item.command, item.x, item.y,
    )  # fmt: skip
    assert MissionItem.from_message(as_int) == item
    from_float = MissionItem.from_message(_wire(item.to_float_message((2, 1))))
    # the float form holds x and y in float32: 35.6 degrees to ~4e-6 (40 in 1e-7 degrees)
    assert abs(from_float.x - item.x) <= 40 and abs(from_float.y - item.y) <= 80
    assert from_float == replace(item, x=from_float.x, y=from_float.y)
    assert row_from_item(item).to_item() == item


def test_x_and_y_are_degrees_only_in_a_global_frame():
    assert _wire(WAYPOINT.to_float_message((2, 1))).x == pytest.approx(35.6123456, abs=1e-5)
    row = row_from_item(SPEED)
    assert (row.x, row.y) == (5.0, 7.0)
    speed = _wire(SPEED.to_float_message((2, 1)))
    assert (speed.x, speed.y) == (5.0, 7.0)


def test_a_float_item_out_of_the_int_fields_range_is_marked_for_rejection():
    message = WAYPOINT.to_float_message((2, 1))
    message.x = 500.0  # degrees: 5e9 in 1e-7 degrees does not fit an int32
    assert MissionItem.from_message(message).x == INT32_MAX
