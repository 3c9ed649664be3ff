"""A scenario's ``faults:``: failures and parameter changes a vehicle applies to itself at a
step boundary, so that a fault study is deterministic.

Each entry names a time, a vehicle, and either a failure (``gps off``: a unit and a type, as
MAV_CMD_INJECT_FAILURE has them) or a parameter value (a live parameter of
:mod:`~mission.config.vehicle_parameters`), with an optional duration after which the unit is
healthy again or the parameter has its earlier value back. Checked here, shape and catalogue;
against the rest of the scenario (vehicles, the run's end, overlaps) by :func:`check_faults`.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass

from mission.config.checks import require
from mission.config.vehicle_parameters import live_parameter_names, parameter_spec

FAILURE_TYPES = {
    "gps": ("off", "stuck", "garbage", "wrong", "delayed"),
    "camera": ("off", "stuck", "wrong"),
}
_VEHICLE = re.compile(r"work|support-([1-9][0-9]*)")  # fullmatch: "$" passes a final newline


@dataclass(frozen=True)
class Fault:
    """From ``at_s`` (simulated seconds), ``vehicle`` has ``failure`` ("UNIT TYPE") or the
    parameter ``param`` set to ``value``; for ``duration_s`` if given, else to the end."""

    at_s: float
    vehicle: str
    failure: str | None = None
    param: str | None = None
    value: float | None = None
    duration_s: float | None = None

    def __post_init__(self) -> None:
        require(math.isfinite(self.at_s) and self.at_s >= 0, "at_s", "must be 0 or more")
        require(
            _VEHICLE.fullmatch(self.vehicle) is not None,
            "vehicle",
            f"must be 'work' or 'support-N', got {self.vehicle!r}",
        )
        if self.duration_s is not None:
            ok = math.isfinite(self.duration_s) and self.duration_s > 0
            require(ok, "duration_s", "must be more than 0 (leave it out: to the end)")
        require(
            (self.failure is None) != (self.param is None),
            "failure",
            "give a failure or a param, one of them",
        )
        if self.failure is not None:
            require(self.value is None, "value", "goes with a param, not a failure")
            unit, _, kind = self.failure.partition(" ")
            kinds = FAILURE_TYPES.get(unit)
            require(kinds is not None, "failure", f"unit must be one of {', '.join(FAILURE_TYPES)}")
            require(kind != "ok", "failure", "a fault is a failure: its end is duration_s")
            require(
                kind in (kinds or ()),
                "failure",
                f"a {unit} failure is one of: {', '.join(kinds or ())}",
            )
            return
        spec = parameter_spec(str(self.param))
        require(
            spec is not None,
            "param",
            f"no parameter {self.param!r} (live ones: {', '.join(live_parameter_names())})",
        )
        assert spec is not None
        require(
            spec.read_only is None,
            "param",
            f"{spec.name} cannot change during a run ({spec.read_only})",
        )
        require(self.value is not None, "value", f"missing: the value {spec.name} is set to")
        refusal = spec.refusal(float(self.value))  # type: ignore[arg-type]
        require(refusal is None, "value", f"{spec.name} {refusal}")

    @property
    def on_camera(self) -> bool:
        """True for a camera failure or a camera parameter (SIM_CAM_*)."""
        return self.target == "camera" or str(self.param).startswith("SIM_CAM_")

    @property
    def target(self) -> str:
        """What the fault acts on: a failure's unit or a parameter's id (``SIM_GPS1_ENABLE``
        turns the gps unit off and on)."""
        if self.failure is not None:
            return self.failure.split(" ")[0]
        return "gps" if self.param == "SIM_GPS1_ENABLE" else str(self.param)

    @property
    def end_s(self) -> float:
        """When the fault ends (infinity: it lasts to the end of the run)."""
        return math.inf if self.duration_s is None else self.at_s + self.duration_s


def check_faults(faults: Sequence[Fault], supports: int, run_end_s: float, step_s: float) -> None:
    """Each fault against the scenario: its vehicle is flown, a camera fault is on a support
    (the work UAV has none), it starts before the run ends and lasts a vehicle step at least
    (``step_s``: a start and its end at one step boundary would end it before it began), and
    no two faults on the same vehicle and unit or parameter overlap (the earlier's end would
    undo the later, an open-ended one's included)."""
    for i, fault in enumerate(faults):
        where = f"faults[{i}]"
        match = _VEHICLE.fullmatch(fault.vehicle)
        number = int(match.group(1)) if match and match.group(1) else 0
        require(
            number <= supports,
            f"{where}.vehicle",
            f"no {fault.vehicle} in this scenario (task.supports = {supports})",
        )
        require(
            not (fault.vehicle == "work" and fault.on_camera),
            f"{where}.{'failure' if fault.failure is not None else 'param'}",
            "the work UAV carries no camera",
        )
        require(
            fault.at_s < run_end_s,
            f"{where}.at_s",
            f"{fault.at_s:g} s is past the run's end (run.timeout_s = {run_end_s:g} s)",
        )
        if fault.duration_s is not None:
            require(
                fault.duration_s >= step_s - 1e-9,
                f"{where}.duration_s",
                f"{fault.duration_s:g} s is shorter than a vehicle step (control.t_cont_s = "
                f"{step_s:g} s)",
            )
    for i, fault in enumerate(faults):
        for j, other in enumerate(faults[:i]):
            if (other.vehicle, other.target) != (fault.vehicle, fault.target):
                continue
            first, second = (other, fault) if other.at_s <= fault.at_s else (fault, other)
            overlap = second.at_s < first.end_s  # an open-ended first ends at infinity
            require(
                not overlap,
                f"faults[{i}]",
                f"overlaps faults[{j}] on {fault.vehicle}'s {fault.target}: one would undo "
                "the other",
            )
