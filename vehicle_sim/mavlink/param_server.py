"""The MAVLink parameter protocol of one vehicle, over its :mod:`~vehicle_sim.mavlink.parameters`.

PARAM_REQUEST_LIST sends every parameter once, with its index and the count; PARAM_REQUEST_READ
answers by index, or by id when the index is -1; PARAM_SET is always answered with the
parameter's PARAM_VALUE, the new value (which the vehicle applies and announces) or, refused,
the unchanged one, with a STATUSTEXT saying why. A read or set of an id the vehicle does not
have gets a STATUSTEXT and no value (there is none to give), as a request of an index out of
range gets nothing. MAVLink FTP gets a NAK at once (:mod:`~vehicle_sim.mavlink.ftp_server`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from vehicle_sim.mavlink.ftp_server import answer_ftp
from vehicle_sim.mavlink.parameters import ParameterTable


class ParamServer:
    """Answers one vehicle's parameter messages."""

    def __init__(
        self,
        table: ParameterTable,
        send: Callable[[Any], None],
        notify: Callable[[int, str], None],
        on_change: Callable[[str, float], None],
        veto: Callable[[str, float], str | None] | None = None,
    ) -> None:
        """``on_change(name, value)`` applies and announces a value once it is set; ``veto``
        (name, value) says why a value in the parameter's range cannot be taken with the
        others as they are (None: it can)."""
        self.table = table
        self._send = send
        self._notify = notify
        self._on_change = on_change
        self._veto = veto

    def handle(self, msg: Any) -> bool:
        """Act on ``msg`` if it is a parameter message (True), else leave it (False)."""
        kind = msg.get_type()
        if kind == "PARAM_REQUEST_LIST":
            for index in range(len(self.table)):
                self._send(self.table.value_message(index))
        elif kind == "PARAM_REQUEST_READ":
            index = msg.param_index if msg.param_index >= 0 else self._named(msg.param_id)
            if index is not None and 0 <= index < len(self.table):
                self._send(self.table.value_message(index))
        elif kind == "PARAM_SET":
            self._set(msg)
        elif kind == "FILE_TRANSFER_PROTOCOL":
            answer_ftp(msg, self._send)
        else:
            return False
        return True

    def _set(self, msg: Any) -> None:
        index = self._named(msg.param_id)
        if index is None:
            return
        name = self.table[index].name
        refusal = self.table.refusal(index, float(msg.param_value), int(msg.param_type))
        if refusal is None and self._veto is not None:
            refusal = self._veto(name, float(msg.param_value))
        if refusal is None:
            value = float(msg.param_value)
            self.table.set(index, value)
            self._on_change(name, value)
        else:
            self._notify(mavlink2.MAV_SEVERITY_WARNING, f"{name} not set: {refusal}")
        self._send(self.table.value_message(index))

    def _named(self, raw: Any) -> int | None:
        """The index of the parameter ``raw`` names (None, said once, for an unknown id)."""
        name = raw.decode("ascii", "replace") if isinstance(raw, bytes) else str(raw)
        name = name.split("\0", 1)[0]
        index = self.table.index_of(name)
        if index is None:
            self._notify(mavlink2.MAV_SEVERITY_WARNING, f"No parameter {name[:16]!r}")
        return index
