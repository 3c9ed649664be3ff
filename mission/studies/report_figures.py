"""The figures of a study's report: each metric against each swept key (mean and 95 % CI,
one line per method and per value of the other keys), and the paired AC - NAC completion-time
difference against how often NAC's fusion let a support in while it was in a zone."""

from __future__ import annotations

import textwrap
from pathlib import Path

from mission.analysis.figures import save_figure
from mission.studies.results import metric_values, paired
from mission.studies.spec import Point, StudySpec, value_text
from mission.studies.stats import bootstrap_ci, mean_ci


def write_figures(
    folder: Path, spec: StudySpec, rows: list[dict], metrics: tuple[tuple[str, str], ...]
) -> list[Path]:
    """Write the figures; return their paths (none without rows). A metric that is 0 in every
    row (a kinematic point's tracking error) draws a flat line and is left out."""
    if not rows:
        return []
    metrics = tuple(
        (column, label)
        for column, label in metrics
        if any(float(r.get(column) or 0) != 0 for r in rows)
    )
    import matplotlib

    matplotlib.use("Agg")
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    scenarios = list(dict.fromkeys(r["scenario"] for r in rows))
    for key in spec.swept_keys:
        values = [_value(p, key) for p in spec.points]
        if not all(_scalar(v) for v in values) or len(set(map(repr, values))) < 2:
            continue  # a mapping per point, or one value for all: nothing to plot
        path = folder / f"metrics-vs-{key}.png"
        _metrics_against(path, spec, rows, scenarios, key, metrics)
        written.append(path)
    if set(spec.methods) == {"ac", "nac"}:
        path = folder / "time-difference-vs-inclusion.png"
        if _difference_against_inclusion(path, spec, rows, scenarios):
            written.append(path)
    for stale in set(folder.glob("*.png")) - set(written):
        stale.unlink()  # from an earlier version of the study
    return written


def _metrics_against(path, spec, rows, scenarios, key, metrics) -> None:
    import matplotlib.pyplot as plt

    values = list(dict.fromkeys(_value(p, key) for p in spec.points))
    numeric = all(isinstance(v, int | float) and not isinstance(v, bool) for v in values)
    positions = {v: (v if numeric else i) for i, v in enumerate(values)}
    varying = _varying_keys(spec)
    names = ["default" if v is None else str(v) for v in values]
    # many long names (a scenario's faults) do not fit under a tick: letters there, the names
    # listed under the panels
    lettered = not numeric and len(names) > 4 and max(map(len, names)) > 24
    key_lines = [f"{chr(65 + i)}: {n}" for i, n in enumerate(names)] if lettered else []
    key_height = 0.16 * len(key_lines) + (0.2 if key_lines else 0.0)
    figure, axes = plt.subplots(
        len(metrics),
        len(scenarios),
        figsize=(4.2 * len(scenarios), 2.6 * len(metrics) + key_height),
        squeeze=False,
    )
    for column_index, scenario in enumerate(scenarios):
        for row_index, (column, label) in enumerate(metrics):
            axis = axes[row_index][column_index]
            for (rest, method), points in _lines(spec, key, varying).items():
                xs, ys, errors = [], [], []
                for number, value in sorted(points, key=lambda point: positions[point[1]]):
                    mine = [
                        r
                        for r in rows
                        if r["scenario"] == scenario
                        and r["point"] == number
                        and r["method"] == method
                    ]
                    mean, half = mean_ci(metric_values(mine, column))
                    if mean is not None:
                        xs.append(positions[value])
                        ys.append(mean)
                        errors.append(half or 0.0)
                if xs:
                    name = method.upper() + (f", {rest}" if rest else "")
                    axis.errorbar(xs, ys, yerr=errors, marker="o", capsize=3, label=name)
            if lettered:
                axis.set_xticks(range(len(values)), [chr(65 + i) for i in range(len(values))])
            elif not numeric:  # a point that does not set the key flies the scenario's default
                axis.set_xticks(range(len(values)), [textwrap.fill(n, 12) for n in names])
                axis.tick_params(axis="x", labelsize=6)
            axis.set_xlabel(key)
            axis.set_ylabel(label, fontsize=8)
            axis.grid(alpha=0.3)
            if row_index == 0:
                axis.set_title(scenario)
    title = f"{spec.name}: each metric against {key} (mean, 95 % CI)"
    _frame(figure, axes, title, key_lines, key_height)
    save_figure(figure, path)


def _frame(figure, axes, title: str, key_lines: list[str], key_height: float) -> None:
    """The title on top (wrapped to the figure's width), the legend of every panel's lines in
    two columns under it, the panels below both, and the names of lettered points (if any)
    under the panels."""
    named = {}  # every line of every panel, once (a method may be missing from the first)
    for axis in (a for row in axes for a in row):
        for handle, label in zip(*axis.get_legend_handles_labels()):
            named.setdefault(label, handle)
    height = figure.get_figheight()
    legend_rows = -(-len(named) // 2)
    lines = textwrap.wrap(title, width=int(11 * figure.get_figwidth()))  # a narrow figure's
    extra = 0.22 * (len(lines) - 1)
    figure.suptitle("\n".join(lines), y=1 - 0.12 / height)
    figure.legend(
        list(named.values()),
        list(named),
        loc="upper center",
        bbox_to_anchor=(0.5, 1 - (0.42 + extra) / height),
        ncol=2,
        fontsize=7,
        frameon=False,
    )
    top = 1 - (0.55 + extra + 0.2 * legend_rows) / height
    if key_lines:
        figure.text(0.02, 0.1 / height, "\n".join(key_lines), fontsize=7, va="bottom")
    figure.tight_layout(rect=(0, key_height / height, 1, top))


def _value(point: Point, key: str) -> object:
    """A point's value of ``key`` as a figure shows it (a scenario's faults told briefly)."""
    value = point.as_dict().get(key)
    return value_text(key, value) if isinstance(value, list) and key == "faults" else value


def _scalar(value: object) -> bool:
    return value is None or isinstance(value, str | int | float | bool)


def _varying_keys(spec: StudySpec) -> set[str]:
    """The keys whose value is not the same in every point (the others name no line)."""
    settings = [point.as_dict() for point in spec.points]
    keys = {key for overrides in settings for key in overrides}
    return {key for key in keys if len({repr(s.get(key)) for s in settings}) > 1}


def _lines(
    spec: StudySpec, key: str, varying: set[str]
) -> dict[tuple[str, str], list[tuple[int, object]]]:
    """{(the other varying keys' values, method): [(point number, this key's value), ...]}."""
    lines: dict[tuple[str, str], list[tuple[int, object]]] = {}
    for number, point in enumerate(spec.points):
        rest = ", ".join(
            f"{k}={value_text(k, v)}" for k, v in point.overrides if k != key and k in varying
        )
        for method in spec.methods:
            lines.setdefault((rest, method), []).append((number, _value(point, key)))
    return lines


def _difference_against_inclusion(path, spec, rows, scenarios) -> bool:
    import matplotlib.pyplot as plt

    figure, axis = plt.subplots(figsize=(6.5, 4.5))
    drawn = False
    for scenario in scenarios:
        xs, ys, low_high = [], [], []
        for number, _ in enumerate(spec.points):
            mine = [r for r in rows if r["scenario"] == scenario and r["point"] == number]
            nac = [r for r in mine if r["method"] == "nac"]
            inclusion, _ = mean_ci(metric_values(nac, "inclusion_rate"))
            a, n = paired(mine, "completion_time_s")
            mean, low, high = bootstrap_ci([x - y for x, y in zip(a, n)])
            if inclusion is None or mean is None:
                continue
            xs.append(inclusion)
            ys.append(mean)
            low_high.append(
                (
                    mean - (low if low is not None else mean),
                    (high if high is not None else mean) - mean,
                )
            )
        if xs:
            drawn = True
            axis.errorbar(xs, ys, yerr=list(zip(*low_high)), fmt="o", capsize=3, label=scenario)
    if not drawn:
        plt.close(figure)
        return False
    axis.axhline(0.0, color="k", lw=0.8)
    axis.set_xlabel("NAC: share of in-zone cycles the fusion let a support in")
    axis.set_ylabel("completion time, AC - NAC [s] (95 % bootstrap CI)")
    axis.set_title(f"{spec.name}: one point per study point and scenario")
    axis.legend()
    axis.grid(alpha=0.3)
    save_figure(figure, path)
    return True
