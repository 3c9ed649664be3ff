"""Unsigned MAVLink 2 packets encoded with fewer Python steps than pymavlink's ``pack``, byte
for byte the packets pymavlink makes.

pymavlink's generated ``pack`` builds the payload with the message's ``struct`` and hands it
to ``MAVLink_message._pack``, which drops the payload's trailing zeros one byte at a time in a
Python loop and builds a header object and a checksum object for every packet. Here the
payload comes from the same ``struct`` with the fields in the same wire order (a recipe made
once per message type: arrays spread, text as its raw bytes), the zeros go in one
``rstrip``, and the header and checksum (``fastcrc``, as pymavlink uses) are packed directly.

Signed links keep pymavlink's ``pack`` (the signature needs its state). Unlike ``pack``, this
leaves the message object as it was (no ``_header`` or ``_msgbuf`` stamped on it): senders
here keep the bytes. Tested against pymavlink for every message type of the dialect.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from typing import Any

from fastcrc.crc16 import mcrf4xx

HEADER = struct.Struct("<BBBBBBBHB")
CHECKSUM = struct.Struct("<H")
MAGIC_V2 = 0xFD

Values = Callable[[Any], tuple]


class FastEncoder:
    """Packs messages of the ardupilotmega dialect as one (system, component) sends them."""

    def __init__(self, system_id: int, component_id: int) -> None:
        self.system_id = system_id
        self.component_id = component_id
        self._recipes: dict[type, tuple[Any, bytes, int, Values]] = {}

    def encode(self, message: Any, sequence: int) -> bytes:
        """The packet of ``message`` with this sequence number."""
        kind = type(message)
        recipe = self._recipes.get(kind) or self._recipe(kind)
        packer, crc_extra, message_id, values = recipe
        payload = packer.pack(*values(message))
        body = payload.rstrip(b"\x00") or payload[:1]  # MAVLink 2 keeps at least one byte
        header = HEADER.pack(
            MAGIC_V2,
            len(body),
            0,
            0,
            sequence,
            self.system_id,
            self.component_id,
            message_id & 0xFFFF,
            message_id >> 16,
        )
        packet = header + body
        return packet + CHECKSUM.pack(mcrf4xx(crc_extra, mcrf4xx(packet[1:])))

    def _recipe(self, kind: type) -> tuple[Any, bytes, int, Values]:
        recipe = (kind.unpacker, bytes([kind.crc_extra]), kind.id, _wire_values(kind))
        self._recipes[kind] = recipe
        return recipe


def _wire_values(kind: type) -> Values:
    """The values a message type's generated ``pack`` hands its ``struct``, in wire order:
    text fields as their raw bytes, other arrays element by element (a short array leaves
    ``struct`` too few values: an error, as in pymavlink's ``pack``). Made as one expression
    over the dialect's own field names, as pymavlink's generated code is."""
    parts = []
    for wire_index, name in enumerate(kind.ordered_fieldnames):  # array_lengths: wire order
        if kind.fieldtypes[kind.fieldnames.index(name)] == "char":  # fieldtypes: field order
            parts.append(f"m._{name}_raw")
        elif kind.array_lengths[wire_index]:
            parts.append(f"*m.{name}[:{kind.array_lengths[wire_index]}]")
        else:
            parts.append(f"m.{name}")
    if not all(name.isidentifier() for name in kind.ordered_fieldnames):
        raise ValueError(f"{kind.__name__}: field names that are not identifiers")
    return eval(f"lambda m: ({', '.join(parts)},)")  # the names are checked above
