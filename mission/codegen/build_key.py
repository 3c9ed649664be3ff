"""A compiled library's cache key made from what its expressions are built from, so that a
cached library loads without building them.

Building the support MPC's NLPs and margins symbolically only to hash them made every ground
station's, MPC helper's and detached run's MPC set-up take 81 ms (5 ms on a keyed hit). The
key here is made of the build's arguments (settings, grid, counts; arrays by their bytes) and
the source text of every module whose code builds the expressions. A key that missed an input
would load a stale solver, so each keyed build lists its modules and a test traces the build,
failing on any project module that runs in it and is not listed.
"""

from __future__ import annotations

import dataclasses
import hashlib
from collections.abc import Iterable
from pathlib import Path
from types import ModuleType

import numpy as np


def build_key(parts: Iterable[object], modules: Iterable[ModuleType]) -> str:
    """The key of a build from these arguments by the code of these modules."""
    lines = [f"{module.__name__} {source_digest(module)}" for module in modules]
    lines += [describe(part) for part in parts]
    return "\n".join(lines)


def source_digest(module: ModuleType) -> str:
    """The SHA-256 of a module's source file."""
    path = module.__file__
    if path is None:
        raise ValueError(f"{module.__name__} has no source file to key a build by")
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def describe(value: object) -> str:
    """A text that changes whenever the value does: dataclasses field by field, arrays by
    dtype, shape and bytes, sequences and mappings item by item, anything else by repr."""
    if isinstance(value, np.ndarray):
        data = hashlib.sha256(np.ascontiguousarray(value).tobytes()).hexdigest()
        return f"array({value.dtype}, {value.shape}, {data})"
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        fields = (
            f"{field.name}={describe(getattr(value, field.name))}"
            for field in dataclasses.fields(value)
        )
        return f"{type(value).__qualname__}({', '.join(fields)})"
    if isinstance(value, dict):
        items = (f"{describe(k)}: {describe(v)}" for k, v in sorted(value.items(), key=repr))
        return "{" + ", ".join(items) + "}"
    if isinstance(value, list | tuple):
        return f"{type(value).__name__}[" + ", ".join(describe(v) for v in value) + "]"
    return repr(value)
