"""``run`` and ``load_run``: a mission flown from Python by the same processes as ``mission run``
(which is a layer over :func:`prepare` and :func:`fly`), and a finished run read back.

Everything that can be checked is checked before any process starts, and bad input raises
:class:`~mission.config.errors.InputError` (a ``ScenarioError`` for the scenario and its
overrides), with one line naming the argument or field and the problem.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from mission.api.run_data import Run
from mission.config.errors import InputError
from mission.config.run_outputs import DEFAULT_SCENARIO, GSnapshots
from mission.config.settings import Scenario
from mission.link.impairment import LinkSettings
from mission.runs.orchestrator import RunOptions
from mission.runs.stall import DEFAULT_STALL_S

RESOLVED_SCENARIO = "resolved-scenario.yaml"  # a run with overrides flies this file
SOURCE = "run()"  # where an error in the arguments of :func:`run` says it is


@dataclass(frozen=True)
class RunPlan:
    """A run checked and ready to fly: its scenario, its options, its folder."""

    scenario: Scenario
    options: RunOptions
    overrides: dict[str, Any]

    @property
    def out(self) -> Path:
        """The run's folder."""
        return self.options.out_dir


def prepare(
    scenario: str | Path = DEFAULT_SCENARIO,
    method: str = "ac",
    seed: int = 0,
    overrides: dict[str, Any] | None = None,
    out: str | Path | None = None,
    *,
    speedup: float | None = None,
    force: bool = False,
    signing_key: str | Path | None = None,
    observer: str | None = None,
    link: LinkSettings | None = None,
    mpc_helper: bool | None = None,
    process_start: Literal["fork", "exec"] = "fork",
    g_snapshots: GSnapshots = "every",
    stall_s: float = DEFAULT_STALL_S,
) -> RunPlan:
    """Every check of a run, nothing written: the scenario and its ``overrides`` (dotted
    keys, validated as YAML is), the method, the seed, the folder, the options."""
    from mission.config.scenario import load_scenario
    from mission.runs.preflight import preflight

    if method not in ("ac", "nac"):
        raise InputError(SOURCE, "method", f"must be 'ac' or 'nac', not {method!r}")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise InputError(SOURCE, "seed", f"must be a whole number >= 0, not {seed!r}")
    overrides = dict(overrides or {})
    reference = str(scenario)
    loaded = load_scenario(reference, overrides)
    preflight(loaded)
    folder = _run_folder(out, f"{loaded.name}-{method}-{seed}", force)
    _check_options(speedup, signing_key, observer)
    if overrides:
        reference = str(folder / RESOLVED_SCENARIO)
    try:
        options = RunOptions(
            reference,
            method,
            seed,
            folder,
            speedup,
            Path(signing_key).resolve() if signing_key else None,
            observer,
            link or LinkSettings(),
            mpc_helper,
            process_start,
            g_snapshots,
            stall_s,
        )
    except ValueError as error:  # RunOptions' own checks
        raise InputError(SOURCE, "", str(error)) from None
    return RunPlan(loaded, options, overrides)


def _check_options(speedup: float | None, key: str | Path | None, observer: str | None) -> None:
    """The real-time speed-up, the signing key's file and the observer's address."""
    from mission.link.mavlink_udp import parse_address
    from mission.link.signing import read_signing_key
    from mission.procs.command_line import check_speedup

    if key is not None:
        read_signing_key(Path(key), "signing_key")  # names the file
    try:
        if speedup is not None:
            check_speedup(speedup, "speedup")
        if observer is not None:
            parse_address(observer, "observer")
    except InputError as error:
        raise InputError(SOURCE, error.where, error.problem) from None
    except ValueError as error:
        raise InputError(SOURCE, "observer", str(error)) from None


def _run_folder(out: str | Path | None, name: str, force: bool) -> Path:
    """The run's folder (default ``logs/NAME-<time>``): one it can write, holding no run
    unless ``force``."""
    from mission.procs.outputs import check_output_dir, run_files_in

    stamp = time.strftime("%Y%m%d-%H%M%S")
    folder = Path(out) if out is not None else Path("logs") / f"{name}-{stamp}"
    try:
        check_output_dir(folder, "out")
    except InputError as error:
        raise InputError(SOURCE, "out", error.problem) from None
    earlier = run_files_in(folder)
    if earlier and not force:
        raise InputError(
            SOURCE,
            "out",
            f"{str(folder)!r} holds a run ({earlier[0].name}): give a new folder, or force "
            "to write over it",
        )
    return folder


def announce(plan: RunPlan) -> str:
    """The line that says a run starts."""
    o = plan.options
    return f"running {plan.scenario.name} ({o.method}, seed {o.seed}) into {plan.out}"


def clear(plan: RunPlan) -> None:
    """Remove an earlier run's files from the run's folder (what else it holds stays): once
    every check has passed, and before anything of this run is written there."""
    from mission.procs.outputs import remove_run_files

    remove_run_files(plan.out)


def fly(plan: RunPlan, live: Any = None) -> dict:
    """Fly a prepared (and cleared) run; its summary. ``live``: a live view's watcher."""
    import yaml

    from mission.config.scenario import load_scenario, resolved_mapping
    from mission.procs.disk_full import fresh, no_space_error, removed_if_disk_fills
    from mission.procs.outputs import remove_run_files
    from mission.runs.orchestrator import run_mission

    out = plan.out
    made = fresh(out)
    try:
        with removed_if_disk_fills(*made):  # a run that could not be written is none
            scenario = plan.scenario
            if plan.overrides:  # the processes fly the scenario with its overrides, a file
                mapping = resolved_mapping(plan.scenario.source, plan.overrides)
                out.mkdir(parents=True, exist_ok=True)
                text = yaml.safe_dump(mapping, sort_keys=False)
                (out / RESOLVED_SCENARIO).write_text(text, encoding="utf-8")
                scenario = load_scenario(plan.options.scenario)
            return run_mission(plan.options, scenario, live)
    except OSError as error:
        if not made and no_space_error(error) is not None:
            remove_run_files(out)  # an out that existed (force): this run's files
        raise


def run(
    scenario: str | Path = DEFAULT_SCENARIO,
    method: str = "ac",
    seed: int = 0,
    overrides: dict[str, Any] | None = None,
    out: str | Path | None = None,
    **options: Any,
) -> Run:
    """Fly a mission as ``mission run`` does (the same processes, the same results) and
    return it as a :class:`~mission.api.run_data.Run`.

    ``scenario``: an embedded name (``along``, ``wall``, ``piers``, ``river``, ...) or a YAML
    path; ``overrides``: dotted settings on top of it, e.g. ``{"world.wind.speed_m_s": 3}``;
    ``out``: the run's folder (default ``logs/<scenario>-<method>-<seed>-<time>/``). Keyword
    ``options`` as :func:`prepare` takes them (``speedup`` for real time, ``force``, ...).
    Raises InputError before anything starts on bad input, and
    :class:`~mission.runs.orchestrator.RunFailed` if a process of the run failed.
    """
    plan = prepare(scenario, method, seed, overrides, out, **options)
    clear(plan)
    fly(plan)
    return load_run(plan.out)


def load_run(path: str | Path, scenario: str | Path | None = None) -> Run:
    """A finished run's folder (made by ``mission run``, a study, or :func:`run`) as a
    :class:`~mission.api.run_data.Run`; ``scenario`` as ``mission analyze --scenario``."""
    from mission.runs.run_files import previous_summary, run_scenario

    folder = Path(path)
    if not (folder / "summary.json").is_file():
        raise InputError(str(folder), "", "no summary.json here (give a run's folder)")
    summary = previous_summary(folder / "summary.json")
    explicit = str(scenario) if scenario is not None else None
    return Run(folder, run_scenario(folder, folder, summary, explicit), summary)
