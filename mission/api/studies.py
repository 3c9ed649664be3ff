"""``study``: a study (a sweep of scenarios x points x methods x seeds) run from Python as
``mission study`` runs it (which is a layer over :func:`conduct`), resumable, and its results
as a DataFrame."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from mission.config.errors import InputError
from mission.studies.execute import KEEP_CHOICES

if TYPE_CHECKING:
    import pandas as pd

    from mission.studies.spec import StudySpec
    from mission.studies.study import StudyOutcome

SOURCE = "study()"
_FLAGS = {"--jobs": "jobs", "--out": "out", "--runs": "runs", "--address": "address"}


@dataclass(frozen=True)
class Study:
    """A study's outputs: ``results.csv`` as a DataFrame, the report and its figures."""

    spec: StudySpec
    out: Path
    finished: int = 0  # runs made by this call
    skipped: int = 0  # runs found done already
    failed: int = 0

    @property
    def results(self) -> pd.DataFrame:
        """results.csv: one row per finished run, every summary metric a column (nested
        ones flattened with dots: ``work_error_m.mean``)."""
        import pandas as pd

        return pd.read_csv(self.out / "results.csv")

    @property
    def report(self) -> Path:
        """report.md: means with their 95 % intervals, AC against NAC paired by seed."""
        return self.out / "report.md"

    @property
    def figures(self) -> list[Path]:
        """The report's figures."""
        return sorted((self.out / "figures").glob("*.png"))

    def run(self, scenario: str, method: str, seed: int, point: int = 0):
        """One of the study's runs (kept with ``keep="all"`` or ``"logs"``) as a Run."""
        from mission.api.runner import load_run

        rows = self.results
        mine = rows[
            (rows["scenario"] == scenario)
            & (rows["method"] == method)
            & (rows["seed"] == seed)
            & (rows["point"] == point)
        ]
        if mine.empty:
            raise KeyError(f"no run {scenario} {method} seed {seed} point {point} in {self.out}")
        key = str(mine.iloc[0]["run_key"])
        folder = self.out / "runs" / f"{scenario}-{method}-{seed}-{key[:10]}"
        return load_run(folder)


def study(
    spec_or_path: str | Path | dict[str, Any],
    engine: str = "local",
    out: str | Path | None = None,
    *,
    jobs: int | None = None,
    keep: str = "all",
    runs: str | Path | None = None,
    address: str | None = None,
) -> Study:
    """Run a study, or resume it (runs found done in ``out`` are not made again), on the
    ``local`` or ``ray`` engine; ``spec_or_path``: a study file, or the mapping such a file
    holds (``{"name": ..., "scenarios": [...], "seeds": 3, ...}``). ``out`` defaults to
    ``results/<name>``. Bad input raises InputError before any run starts."""
    from mission.studies.spec import load_study, study_from_mapping

    if engine not in ("local", "ray"):
        raise InputError(SOURCE, "engine", f"must be 'local' or 'ray', not {engine!r}")
    if keep not in KEEP_CHOICES:
        raise InputError(SOURCE, "keep", f"must be 'all', 'logs' or 'summary', not {keep!r}")
    if isinstance(spec_or_path, dict):
        spec = study_from_mapping(spec_or_path, Path(SOURCE))  # relative paths: from here
    else:
        spec = load_study(Path(spec_or_path))
    folder = Path(out) if out is not None else Path("results") / spec.name
    runs_dir = Path(runs) if runs is not None else None
    try:
        outcome = conduct(spec, folder, engine, keep, runs_dir, jobs, address)
    except InputError as error:
        if error.source != "command line":
            raise
        raise InputError(SOURCE, _FLAGS.get(error.where, error.where), error.problem) from None
    return Study(spec, folder, outcome.finished, outcome.skipped, len(outcome.failed))


def conduct(
    spec: StudySpec,
    out: Path,
    engine: str,
    keep: str,
    runs: Path | None,
    jobs: int | None,
    address: str | None,
) -> StudyOutcome:
    """Check everything, then run the study on the engine (which keys every run before it
    starts any), the canary first; Ctrl-C and SIGTERM stop it, its finished runs kept."""
    from mission.api.study_checks import checked_engine
    from mission.procs.disk_full import fresh, removed_if_disk_fills
    from mission.procs.interrupts import StopRequest
    from mission.studies.study import run_study

    chosen = checked_engine(spec, out, jobs, runs, engine, address)
    made = fresh(out, *([runs] if runs is not None else []))
    with StopRequest(), removed_if_disk_fills(*made):  # a fresh study's start, not kept
        return run_study(spec, out, chosen, keep, runs_dir=runs, canary=True)
