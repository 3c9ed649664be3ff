"""Everything around the two processes, in role packages, and the CLI. Imports: all."""

from __future__ import annotations

from typing import Any

# the Python API, imported when first used: the vehicles and the ground station import
# mission's packages and must not pay for it
_API = {
    "run": "mission.api.runner",
    "load_run": "mission.api.runner",
    "study": "mission.api.studies",
    "Run": "mission.api.run_data",
    "Study": "mission.api.studies",
}
__all__ = list(_API)


def __getattr__(name: str) -> Any:
    if name in _API:
        import importlib

        return getattr(importlib.import_module(_API[name]), name)
    raise AttributeError(f"module 'mission' has no attribute {name!r}")
