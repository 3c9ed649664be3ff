"""``mission study FILE --verify N --against DIR``: make N of a committed study's rows again
with today's code and compare every column but the timings.

The rows are drawn at random with a fixed seed (and listed), or all of them. The canary runs
first: a study whose canary differs from today's is said to be stale at once, with the commit
that made it. Then each row is compared cell by cell, as ``results.csv`` writes it; a
column only today's code writes (a metric added since) is noted, not a difference.
"""

from __future__ import annotations

import random
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TextIO

from mission.config.errors import InputError
from mission.procs.atomic import write_text_atomically
from mission.studies.canary import (
    canary_differences,
    canary_record,
    canary_runs,
    flies_quadrotors,
)
from mission.studies.provenance_file import read_provenance
from mission.studies.results import read_results_csv, result_row, results_csv
from mission.studies.runkeys import StudyRun, code_version
from mission.studies.spec import StudySpec
from mission.studies.study import Engine, finished_summaries, plan_runs

DRAW_SEED = 0  # the rows --verify N draws (the same rows every time)
# the machine's, not the run's: wall and CPU time, solve times, measurement ages (real time),
# where and under which key it ran
TIMING_COLUMNS = frozenset({"wall_time_s", "realtime_factor", "compile_s", "node", "run_key"})
TIMING_PREFIXES = ("mpc_solve_ms.", "measurement_age_ms.")


def is_timing(column: str) -> bool:
    """Whether a results column is a timing (left out of the comparison)."""
    return column in TIMING_COLUMNS or column.startswith(TIMING_PREFIXES)


def row_identity(row: dict[str, Any]) -> tuple[str, int, str, int]:
    """(scenario, point, method, seed): what names a row of a study."""
    return (str(row["scenario"]), int(row["point"]), str(row["method"]), int(row["seed"]))


def run_identity(run: StudyRun) -> tuple[str, int, str, int]:
    """The identity of the row a run makes."""
    return (run.scenario_name, run.point, run.method, run.seed)


def committed_rows(against: Path, runs: list[StudyRun]) -> list[tuple[StudyRun, dict]]:
    """Each row of ``against``'s results.csv with the run of today's study that makes it;
    a row that no run of the study makes is bad input naming the file and the row."""
    source = against / "results.csv"
    if not source.is_file():
        raise InputError("command line", "--against", f"no results.csv in {against}")
    try:
        rows = read_results_csv(source.read_text(encoding="utf-8"))
        identities = [row_identity(row) for row in rows]
    except (OSError, KeyError, TypeError, ValueError) as error:
        raise InputError(str(source), "", f"not a study's results ({error})") from None
    by_identity = {run_identity(run): run for run in runs}
    matched = []
    for number, (row, identity) in enumerate(zip(rows, identities), start=2):
        run = by_identity.get(identity)
        if run is None:
            what = f"{identity[0]} point {identity[1]} {identity[2]} seed {identity[3]}"
            raise InputError(str(source), f"line {number}", f"{what} is not a run of the study")
        matched.append((run, row))
    if not matched:
        raise InputError(str(source), "", "holds no row to verify")
    return matched


def draw(matched: list[tuple[StudyRun, dict]], count: int | None, seed: int = DRAW_SEED):
    """``count`` of the rows drawn at random with ``seed`` (all for None), in study order."""
    if count is None or count >= len(matched):
        return list(matched)
    chosen = sorted(random.Random(seed).sample(range(len(matched)), count))
    return [matched[i] for i in chosen]


@dataclass
class Comparison:
    """What --verify found."""

    differences: list[tuple[str, str, str, str]] = field(default_factory=list)  # run, column
    only_today: set[str] = field(default_factory=set)
    failed: list[str] = field(default_factory=list)
    compared: int = 0


def compare_rows(
    spec: StudySpec, chosen: list[tuple[StudyRun, dict]], today: dict[StudyRun, dict]
) -> Comparison:
    """Every chosen committed row against today's row of the same run, as results.csv
    writes both (``today`` holds today's rows, unwritten)."""
    found = Comparison()
    for run, committed in chosen:
        label = run_label(run)
        if run not in today:
            found.failed.append(label)
            continue
        mine = read_results_csv(results_csv(spec, [today[run]]))[0]
        found.compared += 1
        for column, value in committed.items():
            if is_timing(column):
                continue
            if column not in mine:
                if value is not None:  # an empty cell: the metric this run does not have
                    found.differences.append((label, column, _cell(value), "(no such column)"))
            elif mine[column] != value:
                found.differences.append((label, column, _cell(value), _cell(mine[column])))
        found.only_today |= {c for c in mine if c not in committed and not is_timing(c)}
    return found


def run_label(run: StudyRun) -> str:
    """``along AC seed 9`` (with the point where it is not the first)."""
    point = f" point {run.point}" if run.point else ""
    return f"{run.scenario_name}{point} {run.method.upper()} seed {run.seed}"


def canary_verdict(
    committed: dict[str, Any] | None, summaries: list[dict | None], quadrotors: bool = True
) -> str:
    """What --verify says once the canary is made: the study's canary against today's, run by
    run over the runs both have (those that fly quadrotors only if ``quadrotors``)."""
    today = canary_record(summaries)
    if today["digest"] is None:
        return "canary: FAILED to run; today's decisions are unknown"
    if not committed:
        return f"canary: {today['digest']}; the study has no provenance.json to compare it with"
    commit = str(committed.get("commit") or "an unknown commit")[:12]
    differing = canary_differences(committed.get("canary"), today, quadrotors)
    if differing is None:
        return f"canary: {today['digest']}; the study's canary (commit {commit}) shares no run"
    if not differing:
        return f"canary: {today['digest']}, as when the study was made (commit {commit})"
    return (
        f"canary: STALE: the study was made with commit {commit}; today's code and machine "
        f"decide otherwise in {'; '.join(differing)}, so its numbers may not be today's"
    )


def report_lines(chosen: list[tuple[StudyRun, dict]], found: Comparison) -> list[str]:
    """The diff table and the verdict, as printed."""
    lines = []
    if found.differences:
        lines += ["| run | column | committed | today |", "|---|---|---|---|"]
        lines += [f"| {run} | {column} | {a} | {b} |" for run, column, a, b in found.differences]
        lines.append("")
    differing = len({run for run, *_ in found.differences})
    lines.append(
        f"{found.compared} of {len(chosen)} rows compared: {differing} differ "
        f"({len(found.differences)} cell(s))"
        + (
            f"; {len(found.failed)} failed to run: {', '.join(found.failed)}"
            if found.failed
            else ""
        )
    )
    if found.only_today:
        added = ", ".join(sorted(found.only_today))
        lines.append(f"columns only today's code writes (not compared): {added}")
    return lines


def _cell(value: Any) -> str:
    return "" if value is None else str(value)


@dataclass(frozen=True)
class VerifyOutcome:
    """What a call of :func:`run_verify` found: whether every compared row and the canary
    agree, and the lines it printed."""

    agrees: bool
    lines: list[str]


def run_verify(
    spec: StudySpec,
    against: Path,
    count: int | None,
    out_dir: Path,
    engine: Engine,
    progress: TextIO = sys.stderr,
    runs_dir: Path | None = None,
    seed: int = DRAW_SEED,
) -> VerifyOutcome:
    """Make ``count`` (None: all) of ``against``'s rows again on ``engine``, the canary first,
    into ``out_dir`` (its runs in ``runs_dir``, default ``OUT/runs``); compare, print and write
    ``OUT/verify.md``."""
    code = code_version()
    chosen = draw(committed_rows(against, plan_runs(spec, code)), count, seed)
    committed = read_provenance(against)
    total = len(read_results_csv((against / "results.csv").read_text(encoding="utf-8")))
    if len(chosen) == total:
        heading = f"verifying all {total} rows of {against}"
    else:
        heading = f"verifying {len(chosen)} of {total} rows of {against} (drawn with seed {seed}): "
        heading += ", ".join(run_label(run) for run, _ in chosen)
    progress.write(heading + "\n")
    canaries = canary_runs(code)
    runs_dir = runs_dir or out_dir / "runs"
    out_dir.mkdir(parents=True, exist_ok=True)
    runs_dir.mkdir(parents=True, exist_ok=True)
    wanted = canaries + [run for run, _ in chosen]
    summaries: dict[StudyRun, dict | None] = dict(finished_summaries(wanted, runs_dir))
    verdict: list[str] = []

    def canary_made() -> None:
        if not verdict and all(run in summaries for run in canaries):
            made = [summaries[run] for run in canaries]
            verdict.append(canary_verdict(committed, made, flies_quadrotors(spec)))
            progress.write(verdict[0] + "\n")  # at once, before the rows finish

    def done(run: StudyRun, summary: dict | None, wall: float) -> None:
        summaries[run] = summary
        if run not in canaries:
            progress.write(f"{run_label(run)}: {'made' if summary else 'FAILED'}\n")
        canary_made()

    canary_made()
    pending = [run for run in wanted if run not in summaries]
    if pending:
        engine.run(pending, runs_dir, "logs", done)
    rows = dict(chosen)
    today = {run: result_row(spec, run, s) for run, s in summaries.items() if s and run in rows}
    found = compare_rows(spec, chosen, today)
    lines = [heading, *verdict, "", *report_lines(chosen, found)]
    stale = bool(verdict) and ("STALE" in verdict[0] or "shares no run" in verdict[0])
    agrees = not found.differences and not found.failed and not stale
    lines.append("verified: every compared row is as committed" if agrees else "NOT verified")
    write_text_atomically(out_dir / "verify.md", "\n".join(lines) + "\n")
    return VerifyOutcome(agrees, lines)
