"""Build frozen settings dataclasses from plain YAML data, checking every key and type.

The builder knows a handful of annotation shapes (numbers, strings, booleans, fixed-length
tuples, lists, optionals, literals and nested dataclasses). Every problem is reported as a
:class:`~mission.config.errors.FieldProblem` whose field is the dotted path from the document root,
e.g. ``world.zones[0].min_m``.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import types
import typing
from collections.abc import Mapping
from typing import Any, Literal, TypeVar, get_args, get_origin

from mission.config.errors import FieldProblem

T = TypeVar("T")


def build_settings(cls: type[T], data: Any, path: str = "") -> T:
    """Return an instance of dataclass ``cls`` built from mapping ``data``."""
    if not isinstance(data, Mapping):
        raise FieldProblem(path or "<root>", f"expected a mapping, got {_kind(data)}")
    hints, fields = _shape(cls)
    unknown = sorted(set(map(str, data)) - set(fields))
    if unknown:
        where = _join(path, unknown[0])
        raise FieldProblem(where, f"unknown key (expected one of: {', '.join(sorted(fields))})")
    values: dict[str, Any] = {}
    for name, field in fields.items():
        where = _join(path, name)
        if name not in data:
            if (
                field.default is dataclasses.MISSING
                and field.default_factory is dataclasses.MISSING
            ):
                raise FieldProblem(where, "missing")
            continue
        values[name] = _convert(hints[name], data[name], where)
    try:
        return cls(**values)
    except FieldProblem as problem:
        raise FieldProblem(_join(path, problem.field), problem.problem) from None


@functools.cache  # a class's annotations do not change: each is read once a process
def _shape(cls: type) -> tuple[dict[str, Any], dict[str, dataclasses.Field]]:
    """The type hints and the init fields of dataclass ``cls``."""
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    return typing.get_type_hints(cls), fields


def _convert(annotation: Any, value: Any, where: str) -> Any:
    origin = get_origin(annotation)
    args = get_args(annotation)
    if annotation is Any:
        return value
    if origin in (types.UnionType, typing.Union):
        if value is None and type(None) in args:
            return None
        options = [a for a in args if a is not type(None)]
        if len(options) != 1:
            raise TypeError(f"unsupported union {annotation}")
        return _convert(options[0], value, where)
    if origin is Literal:
        if value not in args:
            choices = ", ".join(repr(a) for a in args)
            raise FieldProblem(where, f"must be one of {choices}, got {value!r}")
        return value
    if origin is tuple:
        return _convert_tuple(args, value, where)
    if origin is list:
        if not isinstance(value, list):
            raise FieldProblem(where, f"expected a list, got {_kind(value)}")
        return [_convert(args[0], item, f"{where}[{i}]") for i, item in enumerate(value)]
    if dataclasses.is_dataclass(annotation):
        return build_settings(annotation, value, where)
    if annotation is float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise FieldProblem(where, f"expected a number, got {_kind(value)}")
        if not math.isfinite(value):
            raise FieldProblem(where, "must be finite")
        return float(value)
    if annotation is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise FieldProblem(where, f"expected an integer, got {_kind(value)}")
        return value
    if annotation is bool:
        if not isinstance(value, bool):
            raise FieldProblem(where, f"expected true or false, got {_kind(value)}")
        return value
    if annotation is str:
        if not isinstance(value, str):
            raise FieldProblem(where, f"expected a string, got {_kind(value)}")
        return value
    raise TypeError(f"unsupported annotation {annotation!r} at {where}")


def _convert_tuple(args: tuple[Any, ...], value: Any, where: str) -> tuple[Any, ...]:
    if not isinstance(value, list | tuple):
        raise FieldProblem(where, f"expected a list, got {_kind(value)}")
    if len(args) == 2 and args[1] is Ellipsis:
        return tuple(_convert(args[0], v, f"{where}[{i}]") for i, v in enumerate(value))
    if len(value) != len(args):
        raise FieldProblem(where, f"expected {len(args)} values, got {len(value)}")
    return tuple(_convert(a, v, f"{where}[{i}]") for i, (a, v) in enumerate(zip(args, value)))


def _join(path: str, name: str) -> str:
    return f"{path}.{name}" if path else name


def _kind(value: Any) -> str:
    if value is None:
        return "nothing (null)"
    if isinstance(value, bool):
        return f"a boolean ({value})"
    if isinstance(value, Mapping):
        return "a mapping"
    if isinstance(value, list):
        return "a list"
    return f"{type(value).__name__} {value!r}"
