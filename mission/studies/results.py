"""``results.csv``: one row per finished run of a study, in the study's order.

A row holds the point's overrides (one column per swept key), the scenario, method and seed,
every metric of the run's summary (nested ones flattened with dots: ``work_error_m.mean``,
``diagnostics.supports.support-1.zone_cycles``), the derived ``inclusion_rate`` (cycles in a
zone that the fusion let a support in, over all supports' cycles in a zone), the wall time,
the node it ran on and its key.
"""

from __future__ import annotations

import csv
import io
from typing import Any

from mission.studies.runkeys import StudyRun
from mission.studies.spec import StudySpec

_LEADING = ["scenario", "point", "method", "seed"]
_TRAILING = ["wall_time_s", "node", "run_key"]
_SKIPPED = {"scenario", "method", "seed", "scenario_source", "study", "link_events", "link"}
_SKIPPED |= {"cpu_s", "compiled"}  # the machine's, like the wall time: no metric of the run
_SKIPPED |= {"provenance"}  # the code's and the machine's: the study's provenance.json


def result_row(spec: StudySpec, run: StudyRun, summary: dict[str, Any]) -> dict:
    """The row of one finished run."""
    row: dict[str, Any] = {key: run.overrides.get(key) for key in spec.swept_keys}
    row.update(scenario=run.scenario_name, point=run.point, method=run.method, seed=run.seed)
    for key, value in _flatten(summary):
        row[key] = value
    row["inclusion_rate"] = inclusion_rate(summary)
    row["wall_time_s"] = summary.get("wall_time_s")
    row["node"] = (summary.get("study") or {}).get("node")
    row["run_key"] = run.key
    return row


def inclusion_rate(summary: dict[str, Any]) -> float | None:
    """Of all supports' control cycles inside a zone, the share the fusion let into S."""
    supports = ((summary.get("diagnostics") or {}).get("supports") or {}).values()
    cycles = sum(s["zone_cycles"] for s in supports)
    fused = sum(s["fused_in_zone"] for s in supports)
    return round(fused / cycles, 4) if cycles else None


def results_csv(spec: StudySpec, rows: list[dict]) -> str:
    """The CSV text: swept keys, the leading columns, metrics (first-seen order), trailing."""
    columns = list(spec.swept_keys) + _LEADING
    for row in rows:
        columns += [k for k in row if k not in columns and k not in _TRAILING]
    columns += _TRAILING
    return csv_text(rows, columns)


def csv_text(rows: list[dict], columns: list[str]) -> str:
    """Rows as CSV text with these columns, a missing or None value as an empty cell (what
    :func:`read_cell` reads back as None)."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=columns, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: "" if row.get(k) is None else row[k] for k in columns})
    return buffer.getvalue()


def read_results_csv(text: str) -> list[dict]:
    """The rows of a results.csv, each value as the summary held it: empty as None, True and
    False as booleans, whole numbers as ints, other numbers as floats, the rest as text."""
    return [
        {key: read_cell(cell) for key, cell in row.items()}
        for row in csv.DictReader(io.StringIO(text))
    ]


def read_cell(cell: str) -> Any:
    """A cell's value as the summary held it (:func:`read_results_csv`)."""
    if cell == "":
        return None
    if cell in ("True", "False"):
        return cell == "True"
    for kind in (int, float):
        try:
            return kind(cell)
        except ValueError:
            pass
    return cell


def _flatten(summary: dict[str, Any], prefix: str = ""):
    for key, value in summary.items():
        name = f"{prefix}{key}"
        if not prefix and key in _SKIPPED:
            continue
        if isinstance(value, dict):
            yield from _flatten(value, f"{name}.")
        elif not isinstance(value, list):
            yield name, value


def metric_values(rows: list[dict], column: str) -> list[float]:
    """The column's numbers (completion time: completed runs only)."""
    if column == "completion_time_s":
        rows = [r for r in rows if r.get("completed")]
    return [float(r[column]) for r in rows if r.get(column) is not None]


def paired(rows: list[dict], column: str) -> tuple[list[float], list[float]]:
    """AC's and NAC's values of seeds where both have one, in seed order."""
    values: dict[str, dict[int, float]] = {"ac": {}, "nac": {}}
    for row in rows:
        if column == "completion_time_s" and not row.get("completed"):
            continue
        if row.get(column) is not None and row["method"] in values:
            values[row["method"]][row["seed"]] = float(row[column])
    seeds = sorted(values["ac"].keys() & values["nac"].keys())
    return [values["ac"][s] for s in seeds], [values["nac"][s] for s in seeds]
