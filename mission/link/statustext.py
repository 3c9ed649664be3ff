"""STATUSTEXT longer than its 50-byte field, both ways: sent in chunks as MAVLink 2 allows
(the same non-zero ``id``, ``chunk_seq`` from 0, the last chunk shorter than the field), and
read back whole."""

from __future__ import annotations

from typing import Any

from pymavlink.dialects.v20 import ardupilotmega as mavlink2

STATUSTEXT_BYTES = 50  # the text field


def statustexts(
    text: str, chunk_id: int, severity: int = mavlink2.MAV_SEVERITY_INFO
) -> list[mavlink2.MAVLink_statustext_message]:
    """``text`` as one STATUSTEXT, or, longer than the field, as chunks with ``chunk_id``
    (1..65535; an empty last chunk after a text of whole chunks)."""
    data = text.encode()
    if len(data) <= STATUSTEXT_BYTES:
        return [mavlink2.MAVLink_statustext_message(severity, data, 0, 0)]
    chunks = [data[i : i + STATUSTEXT_BYTES] for i in range(0, len(data), STATUSTEXT_BYTES)]
    if len(chunks[-1]) == STATUSTEXT_BYTES:
        chunks.append(b"")
    return [
        mavlink2.MAVLink_statustext_message(severity, chunk, chunk_id, seq)
        for seq, chunk in enumerate(chunks)
    ]


class StatusChunks:
    """Reassembles one sender's STATUSTEXTs: :meth:`add` gives the whole text once its last
    chunk is in (at once for an unchunked one), else None."""

    def __init__(self) -> None:
        self._parts: dict[int, list[str]] = {}

    def add(self, message: Any) -> str | None:
        """The whole text this message completes, or None."""
        text = _text(message.text)
        chunk_id = int(getattr(message, "id", 0) or 0)
        if chunk_id == 0:
            return text
        parts = self._parts.setdefault(chunk_id, [])
        if int(getattr(message, "chunk_seq", 0)) == 0:
            parts.clear()  # a new text under a reused id
        parts.append(text)
        if len(text.encode()) < STATUSTEXT_BYTES:
            return "".join(self._parts.pop(chunk_id))
        return None


def _text(value: Any) -> str:
    if isinstance(value, bytes):
        value = value.decode("utf-8", errors="replace")
    return str(value).split("\x00", 1)[0]
