"""Checks a settings dataclass runs on its own fields: each failure is a FieldProblem naming
the field."""

from __future__ import annotations

from mission.config.errors import FieldProblem
from mission.config.vehicle_parameters import parameter_spec


def require(condition: bool, field: str, problem: str) -> None:
    if not condition:
        raise FieldProblem(field, problem)


def positive(owner: object, *names: str) -> None:
    for name in names:
        require(getattr(owner, name) > 0, name, f"must be positive, got {getattr(owner, name)}")


def at_most(owner: object, limit: float, why: str, *names: str) -> None:
    """Each of ``names`` at most ``limit`` (``why``: what the bound stands for)."""
    for name in names:
        value = getattr(owner, name)
        require(value <= limit, name, f"must be at most {limit:g} ({why}), got {value:g}")


def as_parameter(field: str, value: float, parameter: str, unit_note: str = "") -> None:
    """A setting that seeds the vehicles' ``parameter``: in that parameter's range, so that
    a vehicle never starts with a value a PARAM_SET of it would be refused."""
    spec = parameter_spec(parameter)
    assert spec is not None, parameter
    refusal = spec.refusal(value)
    require(refusal is None, field, f"as the vehicles' {parameter} {value:g}{unit_note} {refusal}")


def non_negative(owner: object, *names: str) -> None:
    for name in names:
        value = getattr(owner, name)
        require(value >= 0, name, f"must not be negative, got {value}")
