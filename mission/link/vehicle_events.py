"""The STATUSTEXT a vehicle sends when its sensors or parameters change, and how the analysis
reads it back: ``SOURCE WHAT t=SECONDS``, the vehicle's simulated time (in lockstep, the
ground station's).

Sources: ``Fault`` (the scenario's ``faults:``), ``Set`` (a PARAM_SET from a ground station),
``Failure`` (MAV_CMD_INJECT_FAILURE). WHAT is ``UNIT TYPE`` for a failure (``gps off``,
``camera ok``) or ``ID=VALUE`` for a parameter (``SIM_GPS_UERE=5``).
"""

from __future__ import annotations

import re
from typing import Any

SOURCES = {"Fault": "scenario", "Set": "parameter", "Failure": "command"}
_EVENT = re.compile(r"^(Fault|Set|Failure) (.+) t=(-?\d+(?:\.\d+)?)$")


def event_text(source: str, what: str, time_s: float) -> str:
    """The STATUSTEXT of one change (at most 50 characters for every catalogue id)."""
    if source not in SOURCES:
        raise ValueError(f"unknown event source {source!r}")
    return f"{source} {what} t={time_s:.2f}"


def parameter_change(name: str, value: float) -> str:
    """WHAT of a parameter set to ``value``."""
    return f"{name}={value:g}"


def parse_event(text: str, vehicle: str) -> dict[str, Any] | None:
    """The summary's record of an event STATUSTEXT from ``vehicle`` (None: not an event)."""
    match = _EVENT.match(text)
    if match is None:
        return None
    source, what, time_s = match.groups()
    return {"t": float(time_s), "vehicle": vehicle, "source": SOURCES[source], "event": what}
