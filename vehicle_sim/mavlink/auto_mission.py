"""AUTO: a vehicle flies its uploaded mission, item by item, from the position it believes."""

from __future__ import annotations

from typing import Any

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.link.mission_items import GLOBAL_FRAMES, NAV_POSITION_COMMANDS
from vehicle_sim.mavlink import modes


def fly_mission(vehicle: Any) -> None:
    """One step of AUTO for a :class:`~vehicle_sim.vehicle.Vehicle`: aim at the current item,
    advance past items it cannot fly and items reached, hold in LOITER after the last."""
    server = vehicle.mission
    items, current = server.items, server.current
    if not items:
        return
    if current == 0 and len(items) > 1:
        server.set_current(1)
        current = 1
    item = items[current]
    if item.command not in NAV_POSITION_COMMANDS or item.frame not in GLOBAL_FRAMES:
        if current + 1 < len(items):
            server.set_current(current + 1)
        return
    target = item_position(vehicle, item)
    vehicle.kinematics.target = target
    vehicle.kinematics.target_velocity = None
    acceptance = item.param2 if item.param2 > 0 else vehicle.scenario.control.arrival_tol_m
    if np.linalg.norm(target - vehicle.kinematics.believed) < acceptance:
        if current + 1 < len(items):
            server.set_current(current + 1)
        else:
            vehicle.send(mavlink2.MAVLink_mission_item_reached_message(current))
            vehicle.mode = modes.LOITER
            vehicle.kinematics.hold()
            vehicle.notify(mavlink2.MAV_SEVERITY_INFO, "Mission complete, holding")


def item_position(vehicle: Any, item: Any) -> np.ndarray:
    """ENU position of a global mission item (relative altitudes from the anchor)."""
    alt = item.z
    if item.frame in (
        mavlink2.MAV_FRAME_GLOBAL_RELATIVE_ALT,
        mavlink2.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
    ):
        alt += vehicle.scenario.world.anchor.alt_m
    return vehicle.frame.from_degE7(item.x, item.y, alt)
