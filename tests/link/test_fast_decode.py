"""The fast MAVLink 2 decoder against pymavlink's own parser: the same message objects for every
message type of the dialect, and pymavlink's verdict wherever the fast path steps aside."""

from __future__ import annotations

import math
import random
import struct

import pytest
from fastcrc.crc16 import mcrf4xx
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.link.fast_decode import FastDecoder
from mission.link.fast_encode import FastEncoder
from mission.link.mavlink_udp import MavlinkCodec


def _packet(kind: type, payload: bytes, rng: random.Random) -> bytes:
    """A MAVLink 2 packet as a sender makes it: trailing zeros of the payload dropped."""
    body = payload.rstrip(b"\x00") or b"\x00"
    message_id = kind.id
    header = struct.pack(
        "<BBBBBBBHB",
        0xFD,
        len(body),
        0,
        rng.getrandbits(8),  # compat flags
        rng.getrandbits(8),  # sequence
        rng.getrandbits(8),  # system
        rng.getrandbits(8),  # component
        message_id & 0xFFFF,
        message_id >> 16,
    )
    checksum = mcrf4xx(bytes([kind.crc_extra]), mcrf4xx(header[1:] + body))
    return header + body + struct.pack("<H", checksum)


def _equal(a, b) -> bool:
    """Equal values, NaN equal to NaN, types included (lists element by element)."""
    if type(a) is not type(b):
        return False
    if isinstance(a, list):
        return len(a) == len(b) and all(_equal(x, y) for x, y in zip(a, b))
    if isinstance(a, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    return a == b


def _same_message(fast, reference) -> None:
    assert type(fast) is type(reference)
    ours, theirs = dict(vars(fast)), dict(vars(reference))
    assert vars(ours.pop("_header")) == vars(theirs.pop("_header"))
    assert ours.keys() == theirs.keys()
    for name in ours:
        assert _equal(ours[name], theirs[name]), (reference.get_type(), name)


def _pymavlink_only() -> MavlinkCodec:
    codec = MavlinkCodec(0, 0)
    codec._fast = None
    return codec


def test_every_message_type_decodes_as_pymavlink_decodes_it():
    rng = random.Random(7)
    fast, reference = FastDecoder(), _pymavlink_only()
    checked = set()
    for kind in mavlink2.mavlink_map.values():
        for trial in range(6):
            size = kind.unpacker.size
            payload = bytes(rng.getrandbits(8) if rng.random() < 0.7 else 0 for _ in range(size))
            datagram = _packet(kind, bytes(size) if trial == 0 else payload, rng) * (1 + trial % 3)
            ours = fast.decode(datagram)
            theirs, bad = reference.decode(datagram)
            assert ours is not None and bad == 0 and len(ours) == len(theirs)
            for a, b in zip(ours, theirs):
                _same_message(a, b)
            checked.add(kind)
    assert len(checked) == len(mavlink2.mavlink_map) > 250


def test_a_codec_decodes_real_traffic_as_pymavlink_does():
    sender = MavlinkCodec(2, 1)
    messages = [
        mavlink2.MAVLink_statustext_message(6, b"Contact: structure t=12.5", 0, 0),
        mavlink2.MAVLink_att_pos_mocap_message(5_000_000, [1, 0, 0, 0], 1.5, -2.0, -7.0, [0] * 21),
        mavlink2.MAVLink_gps_raw_int_message(
            1, 3, 356_000_000, 1_397_000_000, 7000, 80, 90, 0, 0, 9
        ),
        mavlink2.MAVLink_system_time_message(1_700_000_000_000_000, 500),
    ]
    datagram = b"".join(sender.encode(m) for m in messages)
    ours, bad = MavlinkCodec(0, 0).decode(datagram)
    theirs, _ = _pymavlink_only().decode(datagram)
    assert bad == 0 and [m.get_type() for m in ours] == [m.get_type() for m in messages]
    for a, b in zip(ours, theirs):
        _same_message(a, b)
    assert ours[0].text == "Contact: structure t=12.5"


@pytest.mark.parametrize(
    "damage",
    ["checksum", "cut short", "trailing byte", "garbage first", "signed flag", "unknown id", "v1"],
)
def test_what_the_fast_path_does_not_take_goes_to_pymavlink(damage):
    sender = MavlinkCodec(2, 1)
    good = sender.encode(mavlink2.MAVLink_system_time_message(1, 500))
    heartbeat = sender.encode(mavlink2.MAVLink_heartbeat_message(2, 3, 0, 0, 0, 3))
    packet = bytearray(good)
    if damage == "checksum":
        packet[-1] ^= 0xFF
    elif damage == "cut short":
        packet = packet[:-3]
    elif damage == "trailing byte":
        packet += b"\x00"
    elif damage == "garbage first":
        packet = b"\x55\x01" + packet
    elif damage == "signed flag":
        packet[2] = 0x01
    elif damage == "unknown id":
        packet[7:10] = (0xFFFFFE).to_bytes(3, "little")
    else:  # a MAVLink 1 heartbeat
        packet = bytes.fromhex("fe09000101000000000002030351040399f2")
    datagram = heartbeat + bytes(packet)
    assert FastDecoder().decode(datagram) is None
    ours, our_bad = MavlinkCodec(0, 0).decode(datagram)
    theirs, their_bad = _pymavlink_only().decode(datagram)
    assert our_bad == their_bad and [m.get_type() for m in ours] == [m.get_type() for m in theirs]


def test_every_message_type_encodes_byte_for_byte_as_pymavlink_packs_it():
    rng = random.Random(11)
    encoder = FastEncoder(17, 42)
    reference = mavlink2.MAVLink(None, srcSystem=17, srcComponent=42)
    decoder = _pymavlink_only()
    for kind in mavlink2.mavlink_map.values():
        for trial in range(4):
            size = kind.unpacker.size
            payload = bytes(rng.getrandbits(8) if rng.random() < 0.6 else 0 for _ in range(size))
            # a message as a sender holds it: decoded from a packet (text as str, arrays as lists)
            (message,), _ = decoder.decode(
                _packet(kind, bytes(size) if trial == 0 else payload, rng)
            )
            reference.seq = sequence = rng.getrandbits(8)
            assert encoder.encode(message, sequence) == bytes(message.pack(reference)), kind


def test_a_short_array_is_refused_as_pymavlink_refuses_it():
    short = mavlink2.MAVLink_att_pos_mocap_message(1, [1, 0, 0, 0], 0.0, 0.0, 0.0, [0.0] * 20)
    with pytest.raises(IndexError):
        short.pack(mavlink2.MAVLink(None, srcSystem=2, srcComponent=1))
    with pytest.raises(struct.error):
        FastEncoder(2, 1).encode(short, 0)
