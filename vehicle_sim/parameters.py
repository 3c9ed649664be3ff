"""A vehicle's parameters: the table the MAVLink parameter protocol serves.

Names follow ArduPilot where it has the same setting (``WPNAV_SPEED``, ``FS_GCS_TIMEOUT``,
``SR0_*``, ``SIM_*``), our own prefix ``SIM_`` where it has none. The table is fixed for a
run: its order, and so every index, never changes once built. Values go on the wire as
ArduPilot sends them (C-cast: an integer parameter's value converted to the float field;
AUTOPILOT_VERSION says MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_C_CAST).

A parameter that would change the run behind the ground station's back is read-only, with the
reason given to whoever tries to set it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.config.settings import Scenario

ID_LENGTH = 16  # param_id: 16 characters, not terminated when all are used
REAL32 = mavlink2.MAV_PARAM_TYPE_REAL32
INT32 = mavlink2.MAV_PARAM_TYPE_INT32
FIXED_FOR_THE_RUN = "fixed for the run: set it in the scenario"
INTEGER_TYPES = {
    mavlink2.MAV_PARAM_TYPE_UINT8,
    mavlink2.MAV_PARAM_TYPE_INT8,
    mavlink2.MAV_PARAM_TYPE_UINT16,
    mavlink2.MAV_PARAM_TYPE_INT16,
    mavlink2.MAV_PARAM_TYPE_UINT32,
    INT32,
}


@dataclass(frozen=True)
class Parameter:
    """One parameter: its id, MAV_PARAM_TYPE, value, the range a set must fall in, and why it
    cannot be set (None: it can)."""

    name: str
    kind: int
    value: float
    low: float
    high: float
    read_only: str | None = FIXED_FOR_THE_RUN

    def __post_init__(self) -> None:
        if not 0 < len(self.name) <= ID_LENGTH or not self.name.isascii():
            raise ValueError(f"parameter id {self.name!r}: 1-{ID_LENGTH} ASCII characters")


class ParameterTable:
    """The parameters in a fixed order, found by index or by id."""

    def __init__(self, parameters: list[Parameter]) -> None:
        self._parameters = list(parameters)
        self._index = {p.name: i for i, p in enumerate(self._parameters)}
        if len(self._index) != len(self._parameters):
            raise ValueError("two parameters share an id")

    def __len__(self) -> int:
        return len(self._parameters)

    def __getitem__(self, index: int) -> Parameter:
        return self._parameters[index]

    def index_of(self, name: str) -> int | None:
        """The index of the parameter named ``name`` (None: there is none)."""
        return self._index.get(name)

    def value(self, name: str) -> float:
        """The value of the parameter named ``name`` (KeyError: there is none)."""
        return self._parameters[self._index[name]].value

    def value_message(self, index: int) -> mavlink2.MAVLink_param_value_message:
        """PARAM_VALUE of the parameter at ``index``."""
        parameter = self._parameters[index]
        return mavlink2.MAVLink_param_value_message(
            parameter.name.encode(), float(parameter.value), parameter.kind, len(self), index
        )

    def refusal(self, index: int, value: float, kind: int) -> str | None:
        """Why ``value`` (sent as MAV_PARAM_TYPE ``kind``) cannot be set at ``index``; None if
        it can."""
        parameter = self._parameters[index]
        if parameter.read_only is not None:
            return parameter.read_only
        if kind != parameter.kind:
            return f"is of type {parameter.kind}, not {kind}"
        if not math.isfinite(value):
            return "needs a finite value"
        if parameter.kind in INTEGER_TYPES and value != round(value):
            return "needs a whole number"
        if not parameter.low <= value <= parameter.high:
            return f"must be in [{parameter.low:g}, {parameter.high:g}]"
        return None

    def set(self, index: int, value: float) -> None:
        """Set a value :meth:`refusal` accepted."""
        old = self._parameters[index]
        self._parameters[index] = Parameter(old.name, old.kind, value, old.low, old.high, None)


def vehicle_parameters(scenario: Scenario, speed_m_s: float, speedup: float) -> ParameterTable:
    """The table of a vehicle of ``scenario`` flying at most ``speed_m_s`` at ``speedup``
    (1 in lockstep): its own settings and the simulation's."""
    v = scenario.vehicle
    step_s = scenario.control.t_cont_s
    rows = [
        # the vehicle's own, under ArduPilot's names (cm/s, as ArduPilot keeps them)
        Parameter("WPNAV_SPEED", REAL32, 100 * speed_m_s, 0, 5000),
        Parameter("FS_GCS_TIMEOUT", REAL32, v.failsafe_s, 0.1, 120, None),  # live
        Parameter("SR0_EXTRA1", INT32, round(v.sensor_hz), 0, 1000),
        Parameter("SR0_EXT_STAT", INT32, round(v.status_hz), 0, 1000),
        Parameter("SIM_RATE_HZ", INT32, round(1 / step_s), 1, 10000),
        # the simulation's
        Parameter("SIM_SPEEDUP", REAL32, speedup, 0.1, 1000, "the run's clock: --speedup"),
        Parameter("SIM_GPS1_ENABLE", INT32, 1, 0, 1, None),  # live: 0 is a GNSS failed off
        Parameter("SIM_GPS1_HZ", INT32, round(v.sensor_hz), 1, 100),
        Parameter("SIM_GPS_UERE", REAL32, scenario.gnss.sigma_uere_m, 0, 100),
        Parameter("SIM_CAM_RANGE", REAL32, scenario.camera.range_m, 0, 1000),
        Parameter("SIM_RADIUS", REAL32, v.radius_m, 0, 10),
        Parameter("SIM_FAIL_ENABLE", INT32, 0, 0, 1, None),  # MAV_CMD_INJECT_FAILURE allowed
        Parameter("SIM_TRACK_NOISE", REAL32, v.tracking_noise_m, 0, 10),
    ]
    return ParameterTable(sorted(rows, key=lambda p: p.name))
