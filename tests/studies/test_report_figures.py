"""The report's figures read right: each line runs left to right, the legend names a line by
the keys that tell it apart, and a point that does not set the swept key says "default"."""

from __future__ import annotations

import io
from pathlib import Path

import pytest

from mission.studies import report_figures
from mission.studies.spec import Point, StudySpec
from mission.studies.study import run_study
from tests.studies.test_study import FakeEngine


@pytest.fixture
def drawn(monkeypatch):
    """The figures as drawn, by file name (not saved)."""
    figures = {}

    def keep(figure, path):
        figures[Path(path).name] = figure

    monkeypatch.setattr(report_figures, "save_figure", keep)
    return figures


def _study(tmp_path, points) -> None:
    spec = StudySpec("t", "", Path("t.yaml"), ("along",), ("ac", "nac"), (0, 1), points, ())
    run_study(spec, tmp_path, FakeEngine(), progress=io.StringIO())


def test_lines_run_in_order_of_the_swept_value_and_are_named_by_what_varies(tmp_path, drawn):
    fixed = ("run.stop_on_crash", False)
    points = tuple(
        Point((("control.clearance_m", clearance), ("control.min_separation_m", separation), fixed))
        for clearance, separation in ((1.0, 2), (0.0, 2), (0.5, 2), (0.5, 0))
    )  # fmt: skip
    _study(tmp_path, points)
    figure = drawn["metrics-vs-control.clearance_m.png"]
    axis = figure.axes[0]
    for line in axis.get_lines():
        xs = list(line.get_xdata())
        assert xs == sorted(xs)
    handles, names = axis.get_legend_handles_labels()  # errorbar containers: [0] the line
    lines = {name: list(handle[0].get_xdata()) for handle, name in zip(handles, names, strict=True)}
    assert lines["AC, control.min_separation_m=2"] == [0.0, 0.5, 1.0]
    labels = [text.get_text() for legend in figure.legends for text in legend.get_texts()]
    assert labels and not any("stop_on_crash" in label for label in labels)


def test_a_point_that_does_not_set_the_key_sits_at_default(tmp_path, drawn):
    points = (Point(()), Point((("control.escape_starts", False),)))
    _study(tmp_path, points)
    axis = drawn["metrics-vs-control.escape_starts.png"].axes[0]
    assert [tick.get_text() for tick in axis.get_xticklabels()] == ["default", "False"]


def test_many_long_point_names_are_letters_under_the_ticks_and_listed_below(tmp_path, drawn):
    faults = [
        [{"at_s": 10, "vehicle": "support-1", "param": "SIM_GPS1_GLTCH_Z", "value": float(size),
          "duration_s": 30}]
        for size in (1, 2, 3, 4, 5)
    ]  # fmt: skip
    _study(tmp_path, tuple(Point((("faults", f),)) for f in faults))
    figure = drawn["metrics-vs-faults.png"]
    ticks = [tick.get_text() for tick in figure.axes[0].get_xticklabels()]
    assert ticks == ["A", "B", "C", "D", "E"]
    listed = "\n".join(text.get_text() for text in figure.texts)
    for letter, size in zip("ABCDE", (1, 2, 3, 4, 5), strict=True):
        assert f"{letter}: support-1 SIM_GPS1_GLTCH_Z={size:g}" in listed


def test_the_legend_names_a_method_missing_from_the_first_panel(tmp_path, drawn, monkeypatch):
    """No NAC run completes, so the first panel (completion time) has AC's line alone: the
    legend still names NAC's lines from the other panels."""
    from tests.studies import test_study

    plain = test_study._summary

    def nac_never_completes(run):
        summary = plain(run)
        if run.method == "nac":
            summary.update(completed=False, completion_time_s=None)
        return summary

    monkeypatch.setattr(test_study, "_summary", nac_never_completes)
    _study(
        tmp_path, (Point((("integrity.enabled", False),)), Point((("integrity.enabled", True),)))
    )
    figure = drawn["metrics-vs-integrity.enabled.png"]
    assert figure.axes[0].get_legend_handles_labels()[1] == ["AC"]
    labels = [text.get_text() for legend in figure.legends for text in legend.get_texts()]
    assert labels == ["AC", "NAC"]


@pytest.mark.parametrize(
    ("metrics", "scenarios", "grid"),
    [(16, 1, (6, 3)), (3, 1, (1, 3)), (1, 1, (1, 1)), (11, 2, (6, 4)), (8, 3, (8, 3))],
)
def test_the_panels_make_a_grid_of_at_least_three_columns(metrics, scenarios, grid):
    assert report_figures.panel_grid(metrics, scenarios) == grid


def test_one_scenarios_many_metrics_are_a_grid_with_its_title_legend_and_panels_apart(
    tmp_path, drawn
):
    """A study of one scenario draws its metrics three to a row (not a strip one panel wide),
    and the title, the legend under it and the panels under both are all inside the figure and
    overlap nothing."""
    _study(tmp_path, (Point((("map.eta", 0.5),)), Point((("map.eta", 1.0),))))
    figure = drawn["metrics-vs-map.eta.png"]
    panels = figure.axes
    assert len(panels) > 3
    assert len({round(axis.get_position().x0, 3) for axis in panels}) == 3
    assert figure.get_figwidth() == pytest.approx(3 * 4.2)
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    whole = figure.bbox
    title = figure._suptitle.get_window_extent(renderer)
    (legend,) = figure.legends
    key = legend.get_window_extent(renderer)
    assert whole.x0 <= title.x0 and title.x1 <= whole.x1 and title.y1 <= whole.y1
    assert key.y1 <= title.y0  # the legend under the title
    highest = max(axis.get_tightbbox(renderer).y1 for axis in panels)
    assert highest <= key.y0  # the panels, their titles and labels under the legend
