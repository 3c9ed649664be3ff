"""Checks a settings dataclass runs on its own fields: each failure is a FieldProblem naming
the field."""

from __future__ import annotations

from mission.config.errors import FieldProblem


def require(condition: bool, field: str, problem: str) -> None:
    if not condition:
        raise FieldProblem(field, problem)


def positive(owner: object, *names: str) -> None:
    for name in names:
        require(getattr(owner, name) > 0, name, f"must be positive, got {getattr(owner, name)}")


def non_negative(owner: object, *names: str) -> None:
    for name in names:
        value = getattr(owner, name)
        require(value >= 0, name, f"must not be negative, got {value}")
