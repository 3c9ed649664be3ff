"""Who a simulated vehicle is: name, instance, MAVLink system id and default ports."""

from __future__ import annotations

import re
from dataclasses import dataclass

BASE_PORT = 14540
TRUTH_PORT_OFFSET = 100
WORK = "work"
_SUPPORT = re.compile(r"^support-([1-9][0-9]*)$")


@dataclass(frozen=True)
class VehicleIdentity:
    """A vehicle's role; work is instance 0, support N is instance N; sysid = instance + 1."""

    name: str
    instance: int

    @classmethod
    def parse(cls, name: str) -> VehicleIdentity:
        """'work' or 'support-N' (N >= 1); ValueError otherwise."""
        if name == WORK:
            return cls(WORK, 0)
        match = _SUPPORT.match(name)
        if not match:
            raise ValueError(f"vehicle must be 'work' or 'support-N' (N >= 1), got {name!r}")
        return cls(name, int(match.group(1)))

    @classmethod
    def from_system_id(cls, system_id: int) -> VehicleIdentity:
        """The identity that uses ``system_id``."""
        return cls(WORK, 0) if system_id == 1 else cls(f"support-{system_id - 1}", system_id - 1)

    @property
    def system_id(self) -> int:
        """MAVLink system id."""
        return self.instance + 1

    @property
    def is_work(self) -> bool:
        """True for the work UAV."""
        return self.instance == 0

    def default_port(self, base_port: int = BASE_PORT) -> int:
        """UDP port the vehicle listens on for MAVLink."""
        return base_port + self.instance

    def default_truth_port(self, base_port: int = BASE_PORT) -> int:
        """UDP port the vehicle listens on for every other vehicle's truth (simulation only:
        the supports' cameras need the work UAV's, contact needs everyone's)."""
        return base_port + TRUTH_PORT_OFFSET + self.instance
