"""MAVLink 2 message signing: the shared secret and how a codec uses it.

A key file holds the 32-byte secret, either as 32 raw bytes or as 64 hexadecimal digits (an
optional trailing newline is allowed). With a key, every packet sent is signed and incoming
packets must carry a valid signature; unsigned heartbeats are still accepted so that an
observer without the key shows up, but nothing else from it is.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from mission.config.errors import InputError

KEY_BYTES = 32
SIGNING_EPOCH_UNIX_S = 1_420_070_400  # 2015-01-01T00:00:00Z, MAVLink's signing epoch
HEARTBEAT_ID = 0


def read_signing_key(path: Path, flag: str = "--signing-key") -> bytes:
    """The secret in ``path``; InputError naming the file and the problem otherwise."""
    try:
        data = Path(path).read_bytes()
    except OSError as error:
        raise InputError(str(path), flag, f"cannot read: {error.strerror}") from None
    if len(data) == KEY_BYTES:
        return data
    text = data.strip()
    if len(text) == 2 * KEY_BYTES:
        try:
            return bytes.fromhex(text.decode("ascii"))
        except (UnicodeDecodeError, ValueError):
            raise InputError(str(path), flag, "64 characters but not hexadecimal") from None
    raise InputError(
        str(path), flag, f"expected 32 raw bytes or 64 hex digits, found {len(data)} bytes"
    )


def enable_signing(mav: Any, key: bytes, link_id: int = 0) -> None:
    """Sign everything ``mav`` sends and accept only signed packets (and unsigned heartbeats)."""
    if len(key) != KEY_BYTES:
        raise ValueError(f"a signing key has {KEY_BYTES} bytes, not {len(key)}")
    signing = mav.signing
    signing.secret_key = key
    signing.sign_outgoing = True
    signing.link_id = link_id
    signing.timestamp = int((time.time() - SIGNING_EPOCH_UNIX_S) * 100_000)
    signing.allow_unsigned_callback = lambda _mav, message_id: message_id == HEARTBEAT_ID


def signing_rejections(mav: Any) -> int:
    """Packets refused so far for a missing or wrong signature."""
    return int(mav.signing.reject_count)
