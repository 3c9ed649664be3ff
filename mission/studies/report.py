"""``report.md`` of a study: per point and method, each metric's mean and 95 % CI; AC against
NAC paired by seed, with a bootstrap CI and the Wilcoxon p; a figure of each metric against
each swept key. Written from ``results.csv``'s rows alone, so the same rows give the same
report (no wall times, no dates).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from mission.procs.atomic import write_text_atomically
from mission.studies.provenance_file import historical_line, report_footer
from mission.studies.report_figures import write_figures
from mission.studies.results import metric_values, paired
from mission.studies.spec import StudySpec
from mission.studies.stats import WILCOXON_METHOD, bootstrap_ci, mean_ci, wilcoxon_p

# (column, what it is); completion time over completed runs only
METRICS = (
    ("completion_time_s", "completion time [s]"),
    ("multipath_steps_total", "steps in multipath"),
    ("work_error_m.mean", "work UAV error, mean [m]"),
    ("inclusion_rate", "fused while in a zone"),
    ("diagnostics.empty_s_cycles", "cycles with S empty"),
    ("diagnostics.time_beyond_flight_s", "time beyond pure flight [s]"),
    ("tracking_error_m.work.p95", "work UAV tracking error, p95 [m]"),
    ("tracking_error_m.supports.p95", "supports' tracking error, p95 [m]"),
    ("safety.closest_approach_min_m", "closest approach of two UAVs [m]"),
    ("safety.least_clearance_min_m", "least clearance of a UAV [m]"),
    ("safety.touching", "contacts (from the truth)"),
)
# shown where a support inspected in some run (dynamic roles)
ROLE_METRICS = (
    ("roles.all_done_s", "all inspection work done [s]"),
    ("roles.support_minutes.inspecting", "support-minutes inspecting"),
    ("roles.role_switches", "role switches"),
    ("roles.work_error_m.shadow.mean", "work UAV error in the shadow, mean [m]"),
)
# shown where the integrity monitor was on in some run
INTEGRITY_METRICS = (
    ("integrity.detected_faults", "lying faults detected"),
    ("integrity.missed_detections", "lying faults missed"),
    ("integrity.time_to_detect_s", "time to detect [s]"),
    ("integrity.false_alarms", "false exclusions"),
    ("integrity.zone_exclusions", "exclusions of a biased fix"),
    ("integrity.protection.work.integrity_events", "work UAV integrity events"),
    ("integrity.protection.supports.integrity_events", "supports' integrity events"),
)
# shown where the multipath came from geometry in some run
GNSS_METRICS = (
    ("gnss_error_steps_total", "supports' fixes off by more than the MDB"),
    ("supports_gnss_error_m.mean", "supports' GNSS error, mean [m]"),
    ("supports_gnss_error_m.p95", "supports' GNSS error, p95 [m]"),
    ("supports_gnss_error_m.max", "supports' GNSS error, max [m]"),
)
PAIRED = ("completion_time_s", "multipath_steps_total", "work_error_m.mean")
GEOMETRY_PAIRED = ("completion_time_s", "gnss_error_steps_total", "work_error_m.mean")


def write_report(
    out_dir: Path,
    spec: StudySpec,
    rows: list[dict],
    failed: int,
    provenance: dict[str, Any] | None = None,
) -> None:
    """report.md and its figures (in ``figures/``); a metric no run has (a study made before
    the metric existed) is left out of both, and so are the roles' where no support
    inspected. With ``provenance``, its footer says where the numbers came from, and a
    historical study says so in the first line."""
    inspected = any(float(r.get("roles.support_minutes.inspecting") or 0) > 0 for r in rows)
    watched = any(r.get("integrity.exclusions") is not None for r in rows)
    geometric = _geometric(rows)
    shown = METRICS + (ROLE_METRICS if inspected else ()) + (INTEGRITY_METRICS if watched else ())
    shown += GNSS_METRICS if geometric else ()
    metrics = tuple(m for m in shown if any(r.get(m[0]) is not None for r in rows))
    figures = write_figures(out_dir / "figures", spec, rows, metrics)
    first = historical_line(provenance)
    lines = ([first, ""] if first else []) + [f"# Study: {spec.name}", ""]
    if spec.description:
        lines += [spec.description, ""]
    lines += [
        f"{len(rows)} of {spec.size} runs finished"
        + (f", {failed} failed" if failed else "")
        + f": {len(spec.scenarios)} scenario(s) x {len(spec.points)} point(s) x "
        f"{len(spec.methods)} method(s) x {len(spec.seeds)} seed(s). "
        "Means with their 95 % confidence interval (Student t); completion time over the "
        "runs that completed.",
        "",
        "## Per point and method",
        "",
        *_means_table(spec, rows, metrics),
    ]
    if set(spec.methods) == {"ac", "nac"}:
        paired_columns = GEOMETRY_PAIRED if geometric else PAIRED
        lines += ["", "## AC against NAC, paired by seed", ""]
        lines += _paired_table(spec, rows, paired_columns)
        lines += ["", f"p: the {WILCOXON_METHOD}."]
    if figures:
        lines += ["", "## Figures", ""]
        lines += [f"![{path.stem}](figures/{path.name})" for path in figures]
    lines += report_footer(provenance)
    write_text_atomically(out_dir / "report.md", "\n".join(lines) + "\n")


def _groups(spec: StudySpec, rows: list[dict]):
    for scenario in dict.fromkeys(r["scenario"] for r in rows):
        for number, point in enumerate(spec.points):
            mine = [r for r in rows if r["scenario"] == scenario and r["point"] == number]
            if mine:
                yield scenario, point.label, mine


def _means_table(spec: StudySpec, rows: list[dict], metrics) -> list[str]:
    header = "| scenario | point | method | runs | completed | " + " | ".join(
        label for _, label in metrics
    )
    lines = [header + " |", "|" + "---|" * (5 + len(metrics))]
    for scenario, label, mine in _groups(spec, rows):
        for method in spec.methods:
            runs = [r for r in mine if r["method"] == method]
            if not runs:
                continue
            done = sum(1 for r in runs if r.get("completed"))
            cells = [_mean_cell(metric_values(runs, column)) for column, _ in metrics]
            lines.append(
                f"| {scenario} | {label} | {method.upper()} | {len(runs)} | {done} | "
                + " | ".join(cells)
                + " |"
            )
    return lines


def _geometric(rows: list[dict]) -> bool:
    """Whether the multipath came from the structure's geometry in some run."""
    return any(r.get("gnss_multipath") in ("geometry", "both") for r in rows)


def _paired_table(spec: StudySpec, rows: list[dict], columns: tuple[str, ...]) -> list[str]:
    lines = [
        "| scenario | point | pairs | "
        + " | ".join(f"{label}: AC - NAC [95 % CI] (p)" for label in _paired_labels(columns))
        + " | NAC fused while in a zone |",
        "|" + "---|" * (4 + len(columns)),
    ]
    for scenario, label, mine in _groups(spec, rows):
        cells, pairs = [], 0
        for column in columns:
            a, n = paired(mine, column)
            pairs = max(pairs, len(a))
            cells.append(_difference_cell(a, n))
        nac = [r for r in mine if r["method"] == "nac"]
        inclusion = _mean_cell(metric_values(nac, "inclusion_rate"))
        lines.append(
            f"| {scenario} | {label} | {pairs} | " + " | ".join(cells) + f" | {inclusion} |"
        )
    return lines


def _paired_labels(columns: tuple[str, ...]) -> list[str]:
    names = dict(METRICS + GNSS_METRICS)
    return [names[c] for c in columns]


def _mean_cell(values: list[float]) -> str:
    mean, half = mean_ci(values)
    if mean is None:
        return "-"
    return _number(mean) if half is None else f"{_number(mean)} +/- {_number(half)}"


def _difference_cell(a: list[float], n: list[float]) -> str:
    mean, low, high = bootstrap_ci([x - y for x, y in zip(a, n)])
    if mean is None:
        return "-"
    base = sum(n) / len(n)
    share = f" ({100 * mean / base:+.1f} %)" if base else ""
    interval = "" if low is None else f" [{_number(low)}, {_number(high)}]"
    p = wilcoxon_p(a, n)
    test = "" if p is None else f" (p = {p:.3g})"
    return f"{_number(mean, signed=True)}{share}{interval}{test}"


def _number(value: float, signed: bool = False) -> str:
    digits = 1 if abs(value) >= 10 else 3 if abs(value) < 1 else 2
    return f"{value:+.{digits}f}" if signed else f"{value:.{digits}f}"
