"""A JSON file that must hold an object (a summary, a study's provenance), read with one line
naming it where it does not."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from mission.config.errors import InputError


def read_json_object(path: Path) -> dict[str, Any] | None:
    """The object ``path`` holds (None where there is no such file); bad input naming the
    file where it cannot be read as JSON or holds something else."""
    if not path.is_file():
        return None
    try:
        found = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as error:
        raise InputError(str(path), "", f"cannot be read as JSON ({error})") from None
    if not isinstance(found, dict):
        raise InputError(str(path), "", "not a JSON object")
    return found
