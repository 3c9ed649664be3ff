"""MAVLink FTP (FILE_TRANSFER_PROTOCOL) as this vehicle offers it: no files. Every request is
answered at once with a NAK (FileNotFound for an open, UnknownCommand for anything else), so a
ground station that tries FTP first (MAVProxy fetches ``@PARAM/param.pck`` so) falls back to
the parameter protocol without waiting out its timeouts."""

from __future__ import annotations

import struct
from collections.abc import Callable
from typing import Any

from pymavlink.dialects.v20 import ardupilotmega as mavlink2

HEADER = struct.Struct("<HBBBBBBI")  # seq, session, opcode, size, req_opcode, burst, pad, offset
NAK = 129
OPEN_OPCODES = {4, 6, 11}  # OpenFileRO, CreateFile, OpenFileWO
FILE_NOT_FOUND = 10
UNKNOWN_COMMAND = 7
PAYLOAD_BYTES = 251


def ftp_nak(msg: Any, target: tuple[int, int]) -> Any | None:
    """The NAK that answers FILE_TRANSFER_PROTOCOL ``msg`` (None: too short to be a request)."""
    payload = bytes(msg.payload)
    if len(payload) < HEADER.size:
        return None
    seq, session, opcode, _, _, _, _, _ = HEADER.unpack_from(payload)
    error = FILE_NOT_FOUND if opcode in OPEN_OPCODES else UNKNOWN_COMMAND
    reply = HEADER.pack((seq + 1) & 0xFFFF, session, NAK, 1, opcode, 0, 0, 0) + bytes([error])
    return mavlink2.MAVLink_file_transfer_protocol_message(
        0, target[0], target[1], list(reply.ljust(PAYLOAD_BYTES, b"\0"))
    )


def answer_ftp(msg: Any, send: Callable[[Any], None]) -> None:
    """Answer one request from its sender."""
    reply = ftp_nak(msg, (msg.get_srcSystem(), msg.get_srcComponent()))
    if reply is not None:
        send(reply)
