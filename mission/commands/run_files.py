"""What the commands that read a finished run share: its summary and its scenario."""

from __future__ import annotations

import json
from pathlib import Path

from mission.config.errors import InputError


def run_scenario(given: Path, run_dir: Path, previous: dict, explicit: str | None):
    """The scenario a run ran: ``--scenario``, else the scenario.yaml a study's run carries,
    else the file or name its summary.json names."""
    from mission.config.scenario import load_scenario

    beside = run_dir / "scenario.yaml"
    source = previous.get("scenario_source")
    if source is not None and not Path(source).is_file():
        source = None  # resolved on another machine (a Ray node's temporary folder)
    scenario_name = (
        explicit
        or (str(beside) if beside.is_file() else None)
        or source
        or previous.get("scenario")
    )
    if scenario_name is None:
        raise InputError(str(given), "--scenario", "unknown scenario: give --scenario")
    return load_scenario(scenario_name)


def previous_summary(path: Path) -> dict:
    """The summary.json beside a tlog ({} if there is none); one line naming it if it is not
    a JSON object."""
    if not path.is_file():
        return {}
    try:
        summary = json.loads(path.read_text(encoding="utf-8"))
    except (ValueError, OSError) as error:
        raise InputError(str(path), "", f"not a readable JSON summary ({error})") from None
    if not isinstance(summary, dict):
        raise InputError(str(path), "", "not a JSON object")
    return summary
