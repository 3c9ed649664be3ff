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


MAX_COLUMNS = 3  # panels side by side, at least (a study of more scenarios: one per scenario)


def panel_grid(metrics: int, scenarios: int) -> tuple[int, int]:
    """(rows, columns) of a metrics figure: each metric a panel per scenario, the scenarios of
    one metric side by side, as many metrics in a row as make at least MAX_COLUMNS columns."""
    per_row = max(1, -(-MAX_COLUMNS // scenarios))
    columns = scenarios * min(per_row, metrics)
    return -(-metrics * scenarios // columns), columns


def _metrics_against(path, spec, rows, scenarios, key, metrics) -> None:
    import matplotlib.pyplot as plt

    values = list(dict.fromkeys(_value(p, key) for p in spec.points))
    numeric = all(isinstance(v, int | float) and not isinstance(v, bool) for v in values)
    positions = {v: (v if numeric else i) for i, v in enumerate(values)}
    names = ["default" if v is None else str(v) for v in values]
    # many long names (a scenario's faults) do not fit under a tick: letters there, the names
    # listed under the panels
    lettered = not numeric and len(names) > 4 and max(map(len, names)) > 24
    key_lines = [f"{chr(65 + i)}: {n}" for i, n in enumerate(names)] if lettered else []
    key_height = 0.16 * len(key_lines) + (0.2 if key_lines else 0.0)
    grid_rows, columns = panel_grid(len(metrics), len(scenarios))
    figure, grid = plt.subplots(
        grid_rows,
        columns,
        figsize=(4.2 * columns, 2.6 * grid_rows + key_height),
        squeeze=False,
    )
    cells = [axis for row in grid for axis in row]
    panels = [(metric, scenario) for metric in metrics for scenario in scenarios]
    lines = _lines(spec, key, _varying_keys(spec))
    for axis, ((column, label), scenario) in zip(cells, panels):
        mine = [r for r in rows if r["scenario"] == scenario]
        _draw_lines(axis, lines, mine, column, positions)
        if lettered:
            axis.set_xticks(range(len(values)), [chr(65 + i) for i in range(len(values))])
        elif not numeric:  # a point that does not set the key flies the scenario's default
            axis.set_xticks(range(len(values)), [textwrap.fill(n, 12) for n in names])
            axis.tick_params(axis="x", labelsize=6)
        axis.set_xlabel(key, fontsize=8)
        axis.set_ylabel(textwrap.fill(label, 34), fontsize=8)
        axis.grid(alpha=0.3)
        if len(scenarios) > 1:
            axis.set_title(scenario, fontsize=9)
    for axis in cells[len(panels) :]:
        figure.delaxes(axis)  # the last row's empty cells
    where = f" in {scenarios[0]}" if len(scenarios) == 1 else ""
    title = f"{spec.name}: each metric against {key}{where} (mean, 95 % CI)"
    _frame(figure, figure.axes, title, key_lines, key_height, columns)
    save_figure(figure, path)


def _draw_lines(axis, lines, rows, column: str, positions: dict) -> None:
    """One metric's mean and CI per line, over ``rows`` (one scenario's)."""
    for (rest, method), points in lines.items():
        xs, ys, errors = [], [], []
        for number, value in sorted(points, key=lambda point: positions[point[1]]):
            mine = [r for r in rows if r["point"] == number and r["method"] == method]
            mean, half = mean_ci(metric_values(mine, column))
            if mean is not None:
                xs.append(positions[value])
                ys.append(mean)
                errors.append(half or 0.0)
        if xs:
            name = method.upper() + (f", {rest}" if rest else "")
            axis.errorbar(xs, ys, yerr=errors, marker="o", capsize=3, label=name)


def _frame(figure, axes, title: str, key_lines: list[str], key_height: float, columns: int) -> None:
    """The title on top (wrapped to the figure's width), the legend of every panel's lines
    under it (in as many columns as the panels, at least two), the panels below both, and the
    names of lettered points (if any) under the panels."""
    named = {}  # every line of every panel, once (a method may be missing from the first)
    for axis in axes:
        for handle, label in zip(*axis.get_legend_handles_labels()):
            named.setdefault(label, handle)
    height = figure.get_figheight()
    legend_columns = max(1, min(len(named), max(2, columns)))
    legend_rows = -(-len(named) // legend_columns)
    lines = textwrap.wrap(title, width=int(11 * figure.get_figwidth()))  # a narrow figure's
    extra = 0.22 * (len(lines) - 1)
    figure.suptitle("\n".join(lines), y=1 - 0.12 / height)
    figure.legend(
        list(named.values()),
        list(named),
        loc="upper center",
        bbox_to_anchor=(0.5, 1 - (0.42 + extra) / height),
        ncol=legend_columns,
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
