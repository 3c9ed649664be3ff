"""Hostile datagrams for the fuzz tests: well-formed packets with nonsense contents, random
bytes, and mutated packets (flipped bits, truncations, garbage prefixes, MAVLink 1 markers)."""

from __future__ import annotations

import math

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.link.mavlink_udp import MavlinkCodec

HOSTILE_FLOATS = [math.nan, math.inf, -math.inf, 1e38, -1e38, 0.0, 1e-38, 12.5]


def _hostile_messages(rng: np.random.Generator, count: int) -> list:
    """Well-formed packets (valid CRC) whose contents are nonsense."""
    f = lambda: float(rng.choice(HOSTILE_FLOATS))  # noqa: E731
    u = lambda bits: int(rng.integers(0, 2**bits, dtype=np.uint64))  # noqa: E731

    def param_id() -> bytes:
        """A real parameter's id half the time, else 16 random bytes."""
        if rng.random() < 0.5:
            return b"FS_GCS_TIMEOUT"
        return rng.integers(0, 256, 16, dtype=np.uint8).tobytes()

    makers = [
        lambda: mavlink2.MAVLink_set_position_target_local_ned_message(
            u(32), 2, 1, u(8), u(16), f(), f(), f(), f(), f(), f(), f(), f(), f(), f(), f()
        ),
        lambda: mavlink2.MAVLink_vision_position_estimate_message(
            u(64), f(), f(), f(), f(), f(), f()
        ),
        lambda: mavlink2.MAVLink_command_long_message(
            2, 1, u(16), u(8), f(), f(), f(), f(), f(), f(), f()
        ),
        lambda: mavlink2.MAVLink_command_int_message(
            2, 1, u(8), u(16), 0, 0, f(), f(), f(), f(), u(31), u(31), f()
        ),
        lambda: mavlink2.MAVLink_mission_count_message(2, 1, u(16), u(8)),
        lambda: mavlink2.MAVLink_mission_item_int_message(
            2,
            1,
            u(16),
            u(8),
            u(16),
            u(8),
            u(8),
            f(),
            f(),
            f(),
            f(),
            u(31) - 2**30,
            u(31) - 2**30,
            f(),
            u(8),
        ),
        lambda: mavlink2.MAVLink_mission_request_int_message(2, 1, u(16), u(8)),
        lambda: mavlink2.MAVLink_mission_set_current_message(2, 1, u(16)),
        lambda: mavlink2.MAVLink_set_mode_message(2, u(8), u(32)),
        lambda: mavlink2.MAVLink_system_time_message(u(64), u(32)),
        lambda: mavlink2.MAVLink_timesync_message(u(63), u(63)),
        lambda: mavlink2.MAVLink_param_set_message(2, 1, param_id(), f(), u(8)),
        lambda: mavlink2.MAVLink_param_request_read_message(2, 1, param_id(), u(16) - 2**15),
        lambda: mavlink2.MAVLink_param_request_list_message(2, 1),
        lambda: mavlink2.MAVLink_file_transfer_protocol_message(
            u(8), 2, 1, list(rng.integers(0, 256, 251, dtype=np.uint8).tobytes())
        ),
    ]
    return [makers[int(rng.integers(len(makers)))]() for _ in range(count)]


def hostile_datagrams(seed: int = 1) -> list[bytes]:
    """10,000 hostile datagrams, shuffled (the same ones for the same seed)."""
    rng = np.random.default_rng(seed)
    codec = MavlinkCodec(255, 190)
    valid = [codec.encode(m) for m in _hostile_messages(rng, 3000)]
    random_bytes = [rng.bytes(int(rng.integers(1, 300))) for _ in range(3000)]
    mutated = []
    for _ in range(4000):
        packet = bytearray(valid[int(rng.integers(len(valid)))])
        kind = int(rng.integers(4))
        if kind == 0:
            for _ in range(int(rng.integers(1, 4))):
                packet[int(rng.integers(len(packet)))] ^= int(rng.integers(1, 256))
        elif kind == 1:
            packet = packet[: int(rng.integers(1, len(packet)))]
        elif kind == 2:
            packet = bytearray(rng.bytes(int(rng.integers(1, 20)))) + packet
        else:
            packet[0] = 0xFE  # MAVLink 1 marker on a MAVLink 2 body
        mutated.append(bytes(packet))
    datagrams = valid + random_bytes + mutated
    rng.shuffle(datagrams)
    return datagrams
