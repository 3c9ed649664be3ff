"""Flight modes, numbered as ArduCopter does so that standard ground stations name them."""

from __future__ import annotations

AUTO = 3
GUIDED = 4
LOITER = 5
PX4_OFFBOARD = 6 << 16  # PX4's custom_mode for OFFBOARD: accepted as GUIDED

NAMES = {AUTO: "AUTO", GUIDED: "GUIDED", LOITER: "LOITER"}


def parse_custom_mode(custom_mode: int) -> int | None:
    """The supported mode a custom_mode asks for, or None."""
    if custom_mode == PX4_OFFBOARD:
        return GUIDED
    return custom_mode if custom_mode in NAMES else None
