"""Unsigned MAVLink 2 datagrams decoded with fewer Python steps than pymavlink's parser, into
the very objects pymavlink makes.

pymavlink parses a datagram a packet at a time through a byte-stream state machine (its
``parse_char``), then ``decode`` works out each message's array and field order afresh. Over
UDP a datagram holds whole packets, so here each packet is cut out by its header, its
checksum computed by ``fastcrc`` (as pymavlink does when it is installed), its payload unpacked
with the message's own ``struct``, and the fields put in order by a recipe made once per
message type. The message is then built and stamped exactly as ``MAVLink.decode`` builds and
stamps it (``_header``, ``_msgbuf``, ``_payload``, ``_crc``, ``_signed``).

Anything this path does not take on whole (a signed packet, MAVLink 1, an unknown message id,
a wrong checksum or length, stray bytes) makes :meth:`FastDecoder.decode` answer None, and the
caller hands the datagram to pymavlink, whose verdict on bad input stays the reference.
Tested against pymavlink's decoding of every message type of the dialect and of a run's tlog.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from fastcrc.crc16 import mcrf4xx
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

MAGIC_V2 = 0xFD
HEADER_BYTES = 10
CHECKSUM_BYTES = 2

Arrange = Callable[[tuple], list]


class FastDecoder:
    """Decodes datagrams of unsigned MAVLink 2 packets of the ardupilotmega dialect."""

    def __init__(self) -> None:
        self._recipes: dict[int, tuple[type, Any, int, bytes, Arrange]] = {}

    def decode(self, datagram: bytes) -> list[Any] | None:
        """The datagram's messages, as pymavlink decodes them; None where this path does not
        take the datagram on whole (pymavlink then decides)."""
        data = bytes(datagram)
        size = len(data)
        offset = 0
        messages = []
        while offset < size:
            if size - offset < HEADER_BYTES + CHECKSUM_BYTES or data[offset] != MAGIC_V2:
                return None
            length, incompat = data[offset + 1], data[offset + 2]
            end = offset + HEADER_BYTES + length + CHECKSUM_BYTES
            if incompat or end > size:  # signed (or unknown flags), or cut short
                return None
            message_id = data[offset + 7] | data[offset + 8] << 8 | data[offset + 9] << 16
            recipe = self._recipes.get(message_id) or self._recipe(message_id)
            if recipe is None:
                return None
            kind, unpacker, wire_size, crc_extra, arrange = recipe
            checksum = data[end - 2] | data[end - 1] << 8
            if mcrf4xx(crc_extra, mcrf4xx(data[offset + 1 : end - 2])) != checksum:
                return None
            payload = data[offset + HEADER_BYTES : end - 2]
            if len(payload) < wire_size:  # MAVLink 2 drops the payload's trailing zeros
                payload += bytes(wire_size - len(payload))
            message = kind(*arrange(unpacker.unpack(payload[:wire_size])))
            packet = bytearray(data[offset:end])
            message._signed = False
            message._msgbuf = packet
            message._payload = packet[6:-2]  # as pymavlink slices it
            message._crc = checksum
            message._header = mavlink2.MAVLink_header(
                message_id,
                0,
                data[offset + 3],
                length,
                data[offset + 4],
                data[offset + 5],
                data[offset + 6],
            )
            messages.append(message)
            offset = end
        return messages

    def _recipe(self, message_id: int) -> tuple[type, Any, int, bytes, Arrange] | None:
        kind = mavlink2.mavlink_map.get(message_id)
        if kind is None:
            return None
        recipe = (
            kind,
            kind.unpacker,
            kind.unpacker.size,
            bytes([kind.crc_extra]),
            _arrangement(kind),
        )
        self._recipes[message_id] = recipe
        return recipe


def _arrangement(kind: type) -> Arrange:
    """How a message type's unpacked wire values become its constructor's arguments:
    wire order to field order, array elements grouped into lists, strings cut at their
    trailing NULs (as ``MAVLink.decode`` does)."""
    orders, lengths = kind.orders, kind.lengths
    starts = [sum(lengths[:i]) for i in range(len(lengths))]
    blank = kind.unpacker.unpack(bytes(kind.unpacker.size))  # a char array is one bytes value
    spans = [
        (starts[order], lengths[order], isinstance(blank[starts[order]], bytes)) for order in orders
    ]

    def arrange(values: tuple) -> list:
        arguments = []
        for start, count, is_text in spans:
            if count == 1:
                value = values[start]
                arguments.append(value.rstrip(b"\x00") if is_text else value)
            else:
                arguments.append(list(values[start : start + count]))
        return arguments

    return arrange
