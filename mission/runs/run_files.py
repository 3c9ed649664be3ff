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
    flown = (str(beside) if beside.is_file() else None) or source or previous.get("scenario")
    scenario_name = explicit or flown
    if scenario_name is None:
        raise InputError(str(given), "--scenario", "unknown scenario: give --scenario")
    scenario = load_scenario(scenario_name)
    if explicit is not None and flown is not None:
        _check_same_flight(scenario, load_scenario(flown), explicit, flown)
    return scenario


def _check_same_flight(given, flown, explicit: str, where: str) -> None:
    """``--scenario`` may change what the run is judged by (its zones), not what it flew:
    its supports, the work UAV's path and the control period are the run's own."""
    for field, mine, theirs in (
        ("task.supports", given.task.supports, flown.task.supports),
        ("task.work_waypoints_m", given.task.work_waypoints_m, flown.task.work_waypoints_m),
        ("control.t_cont_s", given.control.t_cont_s, flown.control.t_cont_s),
    ):
        if mine != theirs:
            raise InputError(
                "command line",
                "--scenario",
                f"{explicit}'s {field} is not the run's ({where}): the run did not fly it",
            )


def previous_summary(path: Path) -> dict:
    """The summary.json beside a tlog ({} if there is none); one line naming it if it is not
    a JSON object."""
    return read_json_object(path) or {}
