"""A vehicle's parameters: the table the MAVLink parameter protocol serves.

Its ids, types, ranges and which can change live come from the catalogue
(:mod:`mission.config.vehicle_parameters`), its values from the scenario. The table is fixed
for a run: its order, and so every index, never changes once built. Values go on the wire as
ArduPilot sends them (C-cast: an integer parameter's value converted to the float field;
AUTOPILOT_VERSION says MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_C_CAST).
"""

from __future__ import annotations

from dataclasses import dataclass

from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.config.autopilot_settings import PX4_PARAMETERS
from mission.config.settings import Scenario
from mission.config.vehicle_parameters import PARAMETERS, ParameterSpec

REAL32 = mavlink2.MAV_PARAM_TYPE_REAL32
INT32 = mavlink2.MAV_PARAM_TYPE_INT32
NUMBER_TYPES = range(mavlink2.MAV_PARAM_TYPE_UINT8, mavlink2.MAV_PARAM_TYPE_REAL64 + 1)


@dataclass(frozen=True)
class Parameter:
    """One parameter of the table: its catalogue entry, MAV_PARAM_TYPE and value."""

    spec: ParameterSpec
    kind: int
    value: float

    @property
    def name(self) -> str:
        """The parameter's id."""
        return self.spec.name


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
        it can. As ArduPilot, any number type is taken and the value converted (C-cast): an
        integer parameter takes an integral value sent as REAL32, which pymavlink's
        ``mavset`` and a MAVProxy without a fetched list send; the value's own checks (whole,
        in range) still hold."""
        parameter = self._parameters[index]
        if parameter.spec.read_only is None and kind not in NUMBER_TYPES:
            return f"param type {kind} unknown"
        return parameter.spec.refusal(value)

    def set(self, index: int, value: float) -> None:
        """Set a value :meth:`refusal` accepted."""
        old = self._parameters[index]
        self._parameters[index] = Parameter(old.spec, old.kind, value)


def vehicle_parameters(
    scenario: Scenario, speed_m_s: float, speedup: float, link_loss: float = 0.0
) -> ParameterTable:
    """The table of a vehicle of ``scenario`` flying at most ``speed_m_s`` at ``speedup``
    (1 in lockstep) and losing ``link_loss`` of what it sends: every parameter of the
    catalogue, sorted by id, valued from the scenario and the command line."""
    v = scenario.vehicle
    values = {
        "FS_GCS_TIMEOUT": v.failsafe_s,
        "WPNAV_SPEED": 100 * speed_m_s,  # cm/s, as ArduPilot keeps it
        "SR0_EXTRA1": round(v.sensor_hz),
        "SR0_EXT_STAT": round(v.status_hz),
        "SIM_RATE_HZ": round(1 / scenario.control.t_cont_s),
        "SIM_SPEEDUP": speedup,
        "SIM_GPS1_ENABLE": 1,
        "SIM_GPS1_HZ": round(v.sensor_hz),
        "SIM_GPS1_LAG_MS": 0,
        "SIM_GPS1_GLTCH_X": 0.0,
        "SIM_GPS1_GLTCH_Y": 0.0,
        "SIM_GPS1_GLTCH_Z": 0.0,
        "SIM_GPS_UERE": scenario.gnss.sigma_uere_m,
        "SIM_MP_SCALE": 1.0,
        "SIM_CAM_RANGE": scenario.camera.range_m,
        "SIM_CAM_NOISE": 1.0,
        "SIM_TRACK_NOISE": v.tracking_noise_m,
        "SIM_WIND_SPD": scenario.world.wind.speed_m_s,
        "SIM_WIND_DIR": scenario.world.wind.from_deg,
        "SIM_WIND_DRYDEN": scenario.world.wind.turbulence,
        "SIM_LINK_LOSS": link_loss,
        "SIM_RADIUS": v.radius_m,
        "SIM_FAIL_ENABLE": 0,
    }
    for name, field in PX4_PARAMETERS.items():
        values[name] = getattr(v.autopilot, field)
    rows = [
        Parameter(spec, INT32 if spec.integer else REAL32, float(values[spec.name]))
        for spec in PARAMETERS
    ]
    return ParameterTable(sorted(rows, key=lambda p: p.name))
