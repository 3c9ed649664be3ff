"""What the commands that read a finished run share: its summary and its scenario."""

from __future__ import annotations

from pathlib import Path

from mission.config.errors import InputError
from mission.procs.json_files import read_json_object


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
    return read_json_object(path) or {}
