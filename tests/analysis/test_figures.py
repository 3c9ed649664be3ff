"""Figures say which run they show and do not mislead: the scenario, method and seed in every
title, NAC's G marked as not learned, faults and contacts marked, every line named (by what it
is, never by a colour's name), titles clear of colour bars, 3-D views at one scale, box plots
with every run and n, and PDF or SVG on ask."""

from __future__ import annotations

import numpy as np
import pytest

from mission.analysis import run_plot
from mission.analysis.metrics import RunTrace
from mission.analysis.run_plot import RunLabel, plot_run
from mission.studies import table3 as batch_table
from mission.world.model import World


def _titles(fig) -> list[str]:
    return [fig._suptitle.get_text()] + [ax.get_title() for ax in fig.axes if ax.get_title()]


@pytest.fixture
def figures(monkeypatch):
    """The figures plot_run makes, by file name, instead of files."""
    made = {}
    monkeypatch.setattr(run_plot, "save_figure", lambda fig, path: made.update({path.name: fig}))
    return made


def _trace() -> RunTrace:
    trace = RunTrace()
    for i, t in enumerate((0.5, 1.0, 1.5)):
        trace.truth[(1, t)] = np.array([-12.0 + 0.1 * i, -3.0, 7.0])
        trace.truth[(2, t)] = np.array([-5.0, 6.5, 8.5])  # in the Along zone
        trace.estimates[t] = np.array([-12.0, -3.0, 7.0])
        trace.ticks.add(t)
    return trace


@pytest.mark.parametrize("method", ["ac", "nac"])
def test_every_title_names_the_run_and_nac_says_g_was_not_learned(
    along, along_world, figures, tmp_path, method
):
    label = RunLabel("along", method, 3)
    g = tmp_path / "g"
    g.mkdir()
    initial = along_world.sigma0_map().sigma_m
    np.save(g / "G_initial.npy", initial)
    final = initial.copy()
    if method == "ac":
        final[5, 30, 8] += 0.7  # one learned voxel near the zone
    np.save(g / "G_final.npy", final)
    plot_run(_trace(), World(along), g, tmp_path / "plots", label)
    assert set(figures) == {"trajectories.png", "error.png", "g_update.png"}
    for fig in figures.values():
        assert fig._suptitle is None or "along, " + method.upper() + ", seed 3" in _titles(fig)[0]
    assert "along, " + method.upper() + ", seed 3" in figures["error.png"].axes[0].get_title()
    texts = " ".join(_titles(figures["trajectories.png"]) + _titles(figures["g_update.png"]))
    colour_bars = [ax for ax in figures["g_update.png"].axes if ax.get_label() == "<colorbar>"]
    if method == "nac":  # no colour bar for a change of nothing (it read 1e-6)
        assert "G not learned (NAC)" in texts and "final G" not in texts
        assert len(colour_bars) == 4  # G before and after, two slices
    else:
        assert "final G" in texts and "1 voxel changed" in texts
        assert len(colour_bars) == 6


def _faulted_trace() -> RunTrace:
    """The trace with support 1's receiver off from 0.5 s to 1.0 s and its crash at 1.2 s."""
    trace = _trace()
    trace.events += [
        {"t": 0.5, "vehicle": "support-1", "source": "scenario", "event": "gps off"},
        {"t": 1.0, "vehicle": "support-1", "source": "scenario", "event": "gps ok"},
    ]
    trace.contacts.append(
        {"t": 1.2, "vehicle": "support-1", "with": "structure", "at_m": [-5.0, 5.2, 8.5],
         "crash": True}
    )  # fmt: skip
    return trace


@pytest.fixture(scope="module")
def faulted(along_world, tmp_path_factory) -> dict:
    """plot_run's figures of the faulted trace (AC, one voxel of G learned), drawn once."""
    made = {}
    tmp_path = tmp_path_factory.mktemp("faulted")
    g = tmp_path / "g"
    g.mkdir()
    initial = along_world.sigma0_map().sigma_m
    np.save(g / "G_initial.npy", initial)
    final = initial.copy()
    final[5, 30, 8] += 0.7
    np.save(g / "G_final.npy", final)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(run_plot, "save_figure", lambda fig, path: made.update({path.name: fig}))
        plot_run(_faulted_trace(), along_world, g, tmp_path / "plots", RunLabel("along", "ac", 3))
    return made


def _legend_labels(fig) -> list[str]:
    legends = [ax.get_legend() for ax in fig.axes if ax.get_legend()] + fig.legends
    return [text.get_text() for legend in legends for text in legend.get_texts()]


def test_faults_and_a_crash_are_marked_where_and_when_they_happened(faulted):
    made = faulted
    error = made["error.png"].axes[0]
    lines = {float(line.get_xdata()[0]) for line in error.get_lines() if line.get_xdata()[0]
             == line.get_xdata()[-1] and len(line.get_xdata()) == 2}  # fmt: skip
    assert {0.5, 1.0, 1.2} <= lines
    texts = " ".join(text.get_text() for text in error.texts)
    assert "support 1: gps off (t = 0.5 s)" in texts
    assert "support 1: touched structure (t = 1.2 s)" in texts
    for name in ("error.png", "trajectories.png"):
        labels = _legend_labels(made[name])
        assert any(label.startswith("scripted fault") for label in labels), name
        assert "crash (the run stopped)" in labels, name
    trajectories = made["trajectories.png"]
    crossed = [
        line
        for ax in trajectories.axes
        for line in ax.get_lines()
        if line.get_marker() == "X" and line.get_linestyle() == "None"
    ]
    assert len(crossed) == 3  # the crash in the 3-D, top and side views
    assert [float(crossed[1].get_xdata()[0]), float(crossed[1].get_ydata()[0])] == [-5.0, 5.2]


def test_every_legend_names_what_a_line_is_and_no_colour(faulted):
    made = faulted
    for name, fig in made.items():
        words = _legend_labels(fig) + [text.get_text() for ax in fig.axes for text in ax.texts]
        assert not any("tab:" in word for word in words), name
    labels = _legend_labels(made["trajectories.png"])
    for vehicle in ("work UAV", "support 1", "multipath zone", "structure"):
        assert vehicle in labels


def test_the_3d_view_has_one_scale_on_every_axis(faulted):
    made = faulted
    (view,) = [ax for ax in made["trajectories.png"].axes if ax.name == "3d"]
    spans = [np.ptp(limits) for limits in (view.get_xlim(), view.get_ylim(), view.get_zlim())]
    aspect = view.get_box_aspect()
    assert aspect / aspect[0] == pytest.approx(np.array(spans) / spans[0])


def test_titles_stay_clear_of_colour_bars_and_inside_the_figure(faulted):
    made = faulted
    for name, fig in made.items():
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        bars = [ax.get_window_extent(renderer) for ax in fig.axes if ax.get_label() == "<colorbar>"]
        for ax in fig.axes:
            if not ax.get_title():
                continue
            title = ax.title.get_window_extent(renderer)
            assert fig.bbox.x0 <= title.x0 and title.x1 <= fig.bbox.x1, (name, ax.get_title())
            assert not any(title.overlaps(bar) for bar in bars), (name, ax.get_title())


def test_box_plots_show_every_run_n_and_start_at_zero(monkeypatch, tmp_path):
    shown = {}
    monkeypatch.setattr("matplotlib.pyplot.close", lambda fig: shown.update(fig=fig))
    rows = [
        {"scenario": "s", "method": m, "seed": seed, "multipath_steps_total": 10 * seed + 5,
         "completion_time_s": 200.0 + seed if seed < 2 else None}
        for m in ("ac", "nac") for seed in range(3)
    ]  # fmt: skip
    batch_table._boxplots(rows, str(tmp_path / "b.png"))
    fig = shown["fig"]
    assert "3 paired seeds" in fig._suptitle.get_text()
    steps, times = fig.axes
    assert [t.get_text() for t in steps.get_xticklabels()] == ["s\nAC\nn = 3", "s\nNAC\nn = 3"]
    assert times.get_xticklabels()[0].get_text().endswith("n = 2")
    points = [line for line in steps.get_lines() if line.get_marker() == "o"]
    assert sum(len(line.get_xdata()) for line in points) == 6
    assert steps.get_ylim()[0] == 0 and times.get_ylim()[0] == 0


@pytest.mark.parametrize(("suffix", "magic"), [(".svg", b"<?xml"), (".pdf", b"%PDF")])
def test_a_world_plot_is_written_as_its_suffix_asks(tmp_path, capsys, suffix, magic):
    from mission.cli import entry_point

    path = tmp_path / f"world{suffix}"
    assert entry_point(["world", "along", "--plot", str(path)]) == 0
    assert path.read_bytes().startswith(magic)
