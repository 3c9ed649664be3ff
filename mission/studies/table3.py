"""The paper's Table 3 from a study's result rows: table.md, table.csv, box plots.

Per scenario and method: mean and std of steps in multipath and of completion time (completed
runs), the completion rate; per scenario, the reduction (NAC - AC) / NAC of the means and a
paired Wilcoxon signed-rank p-value over the seeds both methods finished (for completion time,
the seeds both completed).
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mission.procs.atomic import write_atomically, write_text_atomically
from mission.studies.results import csv_text
from mission.studies.stats import WILCOXON_METHOD, wilcoxon_p


@dataclass(frozen=True)
class Comparison:
    """AC against NAC on one metric in one scenario."""

    reduction_pct: float | None
    p_value: float | None
    pairs: int


@dataclass(frozen=True)
class MethodStats:
    """One scenario-method cell of Table 3."""

    runs: int
    steps_mean: float | None
    steps_std: float | None
    time_mean: float | None
    time_std: float | None
    completion_rate: float | None


def method_stats(rows: list[dict]) -> MethodStats:
    """Mean and std (sample) of steps and completion time, and the completion rate."""
    steps = [r["multipath_steps_total"] for r in rows]
    times = [r["completion_time_s"] for r in rows if r["completed"]]
    return MethodStats(
        len(rows),
        _mean(steps),
        _std(steps),
        _mean(times),
        _std(times),
        len(times) / len(rows) if rows else None,
    )


def compare(ac: dict[int, float | None], nac: dict[int, float | None]) -> Comparison:
    """Reduction of the means over paired seeds and the Wilcoxon signed-rank p-value."""
    seeds = sorted(s for s in ac.keys() & nac.keys() if ac[s] is not None and nac[s] is not None)
    if not seeds:
        return Comparison(None, None, 0)
    a = [float(ac[s]) for s in seeds]
    n = [float(nac[s]) for s in seeds]
    mean_n = statistics.fmean(n)
    reduction = 100 * (mean_n - statistics.fmean(a)) / mean_n if mean_n else None
    return Comparison(reduction, wilcoxon_p(a, n), len(seeds))


def table_rows(rows: list[dict]) -> list[dict]:
    """table.csv: one row per scenario and method; the comparison on the AC row."""
    out = []
    for scenario in _unique(r["scenario"] for r in rows):
        mine = [r for r in rows if r["scenario"] == scenario]
        by_method = {m: [r for r in mine if r["method"] == m] for m in ("ac", "nac")}
        steps = compare(*(_by_seed(by_method[m], "multipath_steps_total") for m in ("ac", "nac")))
        times = compare(*(_by_seed(by_method[m], "completion_time_s") for m in ("ac", "nac")))
        for method in _unique(r["method"] for r in mine):
            stats = method_stats([r for r in mine if r["method"] == method])
            is_ac = method == "ac"
            out.append(
                {
                    "scenario": scenario,
                    "method": method,
                    "runs": stats.runs,
                    "steps_mean": _round(stats.steps_mean),
                    "steps_std": _round(stats.steps_std),
                    "completion_time_mean_s": _round(stats.time_mean),
                    "completion_time_std_s": _round(stats.time_std),
                    "completion_rate": _round(stats.completion_rate),
                    "steps_reduction_pct": _round(steps.reduction_pct) if is_ac else None,
                    "steps_wilcoxon_p": _round(steps.p_value, 4) if is_ac else None,
                    "time_reduction_pct": _round(times.reduction_pct) if is_ac else None,
                    "time_wilcoxon_p": _round(times.p_value, 4) if is_ac else None,
                    "pairs": steps.pairs if is_ac else None,
                    "time_pairs": times.pairs if is_ac else None,
                }
            )
    return out


def table_markdown(table: list[dict]) -> str:
    """The table as Markdown, in the paper's Table 3 layout."""
    lines = [
        "| scenario | method | runs | steps in multipath | completion time [s] | completed |"
        " steps, AC vs NAC (p) | time, AC vs NAC (p) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in table:
        steps = _pm(r["steps_mean"], r["steps_std"])
        time = _pm(r["completion_time_mean_s"], r["completion_time_std_s"])
        rate = "-" if r["completion_rate"] is None else f"{100 * r['completion_rate']:.0f} %"
        lines.append(
            f"| {r['scenario']} | {r['method'].upper()} | {r['runs']} | {steps} | {time} | {rate} "
            f"| {_reduction(r['steps_reduction_pct'], r['steps_wilcoxon_p'], r['pairs'])} "
            f"| {_reduction(r['time_reduction_pct'], r['time_wilcoxon_p'], r['time_pairs'])} |"
        )
    lines += ["", f"p: the {WILCOXON_METHOD}."]
    return "\n".join(lines) + "\n"


def write_tables(out_dir: Path, rows: list[dict]) -> None:
    """(Re)write table.md, table.csv and boxplots.png from a study's result rows."""
    table = table_rows(rows)
    columns = list(table[0]) if table else ["scenario", "method", "runs"]
    write_text_atomically(out_dir / "table.csv", csv_text(table, columns))
    write_text_atomically(out_dir / "table.md", table_markdown(table))
    if rows:
        write_atomically(out_dir / "boxplots.png", lambda temp: _boxplots(rows, temp))


def _boxplots(rows: list[dict], path: str) -> None:
    """Steps in multipath and completion time per scenario and method: a box each, every
    run's value as a point over it, n under each box, both axes from 0."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenarios = _unique(r["scenario"] for r in rows)
    figure, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    metrics = [
        ("multipath_steps_total", "steps in multipath"),
        ("completion_time_s", "completion time [s] (completed runs)"),
    ]
    for axis, (key, label) in zip(axes, metrics):
        data, names = [], []
        for scenario in scenarios:
            for method in ("ac", "nac"):
                mine = [r for r in rows if r["scenario"] == scenario and r["method"] == method]
                values = [r[key] for r in mine if r[key] is not None]
                data.append(values or [math.nan])
                names.append(f"{scenario}\n{method.upper()}\nn = {len(values)}")
        axis.boxplot(data, showfliers=False)
        for position, values in enumerate(data, start=1):
            spread = (
                0.3 * (np.arange(len(values)) - (len(values) - 1) / 2) / max(len(values) - 1, 1)
            )
            axis.plot(position + spread, values, "o", ms=3, color="k", alpha=0.6)
        axis.set_xticks(range(1, len(names) + 1), names)
        axis.set_ylabel(label)
        axis.set_ylim(bottom=0)
        axis.grid(axis="y", alpha=0.3)
    seeds = len({r["seed"] for r in rows})
    figure.suptitle(f"AC and NAC over {seeds} paired seeds: every run a point")
    figure.tight_layout()
    figure.savefig(path, format="png", dpi=100)
    plt.close(figure)


def _by_seed(rows: list[dict], key: str) -> dict[int, float | None]:
    return {r["seed"]: r[key] for r in rows}


def _unique(values: Iterable[str]) -> list[str]:
    return list(dict.fromkeys(values))


def _mean(values: list[float]) -> float | None:
    return statistics.fmean(values) if values else None


def _std(values: list[float]) -> float | None:
    return statistics.stdev(values) if len(values) > 1 else None


def _round(value: float | None, digits: int = 2) -> float | None:
    return None if value is None else round(value, digits)


def _pm(mean: float | None, std: float | None) -> str:
    if mean is None:
        return "-"
    return f"{mean:.1f}" if std is None else f"{mean:.1f} +/- {std:.1f}"


MIN_PAIRS_FOR_5_PERCENT = 6  # below, no two-sided signed-rank p can reach 0.05 (2 / 2^n)


def _reduction(percent: float | None, p: float | None, pairs: int | None) -> str:
    if percent is None:
        return ""
    change = -percent  # shown as the paper does: AC's change against NAC
    if p is None:
        return f"{change:+.1f} %"
    if pairs is not None and pairs < MIN_PAIRS_FOR_5_PERCENT:
        return f"{change:+.1f} % (p = {p:.3g}; {pairs} pairs: too few for the test to mean much)"
    return f"{change:+.1f} % (p = {p:.3g})"
