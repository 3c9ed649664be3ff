"""The paper's figures for one run, from its tlog and G snapshots (``mission analyze --plots``).

- ``trajectories.png`` (Figs. 6-9): 3-D (equal scales), top and side views of every UAV's true
  path with the bridge, the zones and the final G as background, each fault where its vehicle
  was and each contact where it happened;
- ``error.png``: the work UAV's localization error per control cycle, the cycles each support
  spent in a zone shaded in its colour, a line at each fault and contact;
- ``g_update.png`` (Fig. 10): G before and after the run through the most-changed voxel, and the
  voxels the updates touched.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

from mission.analysis.figures import save_figure
from mission.analysis.metrics import RunTrace, work_errors, zone_steps
from mission.analysis.run_marks import Mark, legend_handles, mark_places, mark_times, run_marks
from mission.analysis.world_plot import draw_background
from mission.world.model import Sigma0Map, World

COLORS = {1: "tab:red", 2: "tab:blue", 3: "tab:green", 4: "tab:purple", 5: "tab:olive"}
AXES = "xyz"
FIGURES = ("trajectories.png", "error.png", "g_update.png")  # what plot_run writes
MARKS_LISTED = 8  # faults and contacts listed under the trajectories' legend


@dataclass(frozen=True)
class RunLabel:
    """Which run a figure shows: every title says it."""

    scenario: str
    method: str | None  # "ac", "nac", or None when unknown
    seed: int | None

    def __str__(self) -> str:
        method = (self.method or "method unknown").upper()
        seed = "seed unknown" if self.seed is None else f"seed {self.seed}"
        return f"{self.scenario}, {method}, {seed}"

    @property
    def learns(self) -> bool:
        """False for NAC, the baseline that never updates G."""
        return self.method != "nac"


def plot_run(
    trace: RunTrace, world: World, g_dir: Path, out_dir: Path, label: RunLabel
) -> list[Path]:
    """Write the three figures into ``out_dir``; return their paths."""
    out_dir.mkdir(parents=True, exist_ok=True)
    sigma0 = world.sigma0_map()
    initial, final = _snapshots(g_dir, sigma0)
    paths = [out_dir / name for name in FIGURES]
    _trajectories(trace, world, dataclasses.replace(sigma0, sigma_m=final), paths[0], label)
    _error(trace, world, paths[1], label)
    _g_update(world, sigma0, initial, final, paths[2], label)
    return paths


def _snapshots(g_dir: Path, sigma0: Sigma0Map) -> tuple[np.ndarray, np.ndarray]:
    """G at the start and the end (sigma_0 for both when the run kept no snapshots)."""
    shape = sigma0.grid.shape
    initial = _load(g_dir / "G_initial.npy", shape)
    final = _load(g_dir / "G_final.npy", shape)
    if final is None:
        numbered = sorted(g_dir.glob("G_[0-9]*.npy"))
        final = _load(numbered[-1], shape) if numbered else None
    base = sigma0.sigma_m.reshape(shape)
    initial = base if initial is None else initial
    return initial, initial if final is None else final


def _load(path: Path, shape: tuple[int, ...]) -> np.ndarray | None:
    try:
        values = np.load(path)
    except (OSError, ValueError):
        return None
    return values.reshape(shape) if values.size == np.prod(shape) else None


def _label(system: int) -> str:
    return "work UAV" if system == 1 else f"support {system - 1}"


def _trajectories(
    trace: RunTrace, world: World, g_map: Sigma0Map, path: Path, label: RunLabel
) -> None:
    fig = plt.figure(figsize=(15, 11))
    marks = run_marks(trace)
    systems = [1, *trace.supports]
    _view_3d(fig.add_subplot(2, 2, 1, projection="3d"), trace, world, marks)
    level = _support_level(trace)
    views = [(0, 1, 2, "top view (x-y)", 2), (0, 2, 1, "side view (x-z)", 3)]
    for a, b, normal, title, slot in views:
        ax = fig.add_subplot(2, 2, slot)
        point = np.full(3, level) if normal == 2 else _zone_centre(world, level)
        k = draw_background(ax, world, g_map, point, a, b, normal, alpha=0.55, label="G [m]")
        for system in systems:
            _, points = trace.track(system)
            if len(points):
                ax.plot(points[:, a], points[:, b], color=COLORS.get(system, "k"), lw=1)
        mark_places(ax, marks, trace, (a, b))
        ax.set_xlabel(f"{AXES[a]} [m]")
        ax.set_ylabel(f"{AXES[b]} [m]")
        centre = g_map.grid.axis_centers(normal)[k]
        shown = "final G" if label.learns else "sigma_0 (G not learned, NAC)"
        ax.set_title(f"{title}; {shown} at {AXES[normal]} = {centre:g} m", fontsize=11)
        ax.set_aspect("equal")
    _legend_panel(fig.add_subplot(2, 2, 4), trace, marks)
    background = "the final G" if label.learns else "sigma_0: G not learned (NAC)"
    fig.suptitle(f"{label}: trajectories, zones and {background}")
    fig.tight_layout()
    _save(fig, path)


def _view_3d(ax, trace: RunTrace, world: World, marks: list[Mark]) -> None:
    """The structure, the zones, every UAV's true path and the marks, at one scale on all
    three axes."""
    triangles = world.structure.mesh.triangles
    ax.add_collection3d(Poly3DCollection(triangles, facecolor="0.6", alpha=0.15))
    extent = [triangles.reshape(-1, 3)]
    for system in [1, *trace.supports]:
        _, points = trace.track(system)
        if len(points):
            ax.plot(*points.T, color=COLORS.get(system, "k"))
            extent.append(points)
    for zone in world.scenario.world.zones:
        _box3d(ax, np.array(zone.min_m), np.array(zone.max_m))
        extent.append(np.array([zone.min_m, zone.max_m]))
    mark_places(ax, marks, trace, (0, 1, 2))
    everything = np.vstack(extent)
    low, high = everything.min(axis=0), everything.max(axis=0)
    span = np.maximum(high - low, 1.0)
    ax.set_xlim(low[0], low[0] + span[0])
    ax.set_ylim(low[1], low[1] + span[1])
    ax.set_zlim(low[2], low[2] + span[2])
    ax.set_box_aspect(tuple(span), zoom=1.2)  # a metre as long on every axis
    ax.view_init(elev=25, azim=-120)  # from the south-west: the z axis on the left
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.set_title("3-D view (true positions, equal scales)")


def _error(trace: RunTrace, world: World, path: Path, label: RunLabel) -> None:
    """The work UAV's error over time, each support's cycles in a zone shaded in its colour,
    each fault and contact a line."""
    times, errors = work_errors(trace)
    steps = zone_steps(trace, world)
    fig, ax = plt.subplots(figsize=(13, 4.2))
    half = world.scenario.control.t_cont_s / 2
    (line,) = ax.plot(times, errors, color="k", lw=0.8, label="|xhat - x|")
    handles = [line]
    for system in sorted(steps):
        color = COLORS.get(system, "0.5")
        for t in steps[system]:
            ax.axvspan(t - half, t + half, color=color, alpha=0.25, lw=0)
        name = f"support {system - 1} in a zone ({len(steps[system])} cycles)"
        handles.append(Patch(color=color, alpha=0.25, label=name))
    handles += mark_times(ax, run_marks(trace))
    ax.set_xlabel("simulated time [s]")
    ax.set_ylabel("work UAV localization error [m]")
    total = len({t for cycle_times in steps.values() for t in cycle_times})
    ax.set_title(f"{label}: {total} cycles with a support in a zone")
    ax.grid(alpha=0.3)
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    fig.tight_layout()
    _save(fig, path)


def _g_update(
    world: World,
    sigma0: Sigma0Map,
    initial: np.ndarray,
    final: np.ndarray,
    path: Path,
    label: RunLabel,
) -> None:
    change = final - initial
    grid = sigma0.grid
    updated = int(np.count_nonzero(change))
    if updated:  # through the most-changed voxel
        index = np.unravel_index(int(np.argmax(np.abs(change))), change.shape)
    else:  # through the zone, where a learning G would have changed
        index = tuple(int(i) for i in grid.index_of(_zone_centre(world, 7.5)[None])[0])
    point = grid.origin_m + grid.voxel_m * (np.array(index) + 0.5)  # the voxel's centre
    fig, axes = plt.subplots(2, 3, figsize=(16, 9))
    panels = [("before", initial), ("after", final)]
    for row, (a, b, normal) in enumerate(((0, 1, 2), (0, 2, 1))):
        for col, (name, values) in enumerate(panels):
            ax = axes[row, col]
            g_map = dataclasses.replace(sigma0, sigma_m=values)
            draw_background(ax, world, g_map, point, a, b, normal, label="G [m]")
            ax.set_title(f"G {name}, {AXES[normal]} = {point[normal]:g} m", fontsize=11)
            ax.set_aspect("equal")
            if col == 0 and ax.get_legend_handles_labels()[0]:
                ax.legend(loc="upper right", fontsize=7)  # the zones' boxes
        _change_panel(axes[row, 2], np.take(change, int(index[normal]), axis=normal), grid, a, b)
        slice_at = f"{AXES[normal]} = {point[normal]:g} m"
        axes[row, 2].set_title(_change_title(updated, label, slice_at), fontsize=11)
        for ax in axes[row]:
            ax.set_xlabel(f"{AXES[a]} [m]")
            ax.set_ylabel(f"{AXES[b]} [m]")
    fig.suptitle(f"{label}: the GNSS-localizability map G")
    fig.tight_layout()
    _save(fig, path)


def _change_title(updated: int, label: RunLabel, slice_at: str) -> str:
    """Two short lines: a title as wide as its panel, clear of the colour bar beside it."""
    if updated:
        voxels = "voxel" if updated == 1 else "voxels"
        return f"G after - before, {slice_at}\n({updated} {voxels} changed in the whole map)"
    said = "G not learned (NAC): no change" if not label.learns else "G unchanged"
    return f"{said}\n{slice_at}"


def _change_panel(ax, delta: np.ndarray, grid, a: int, b: int) -> None:
    """G after - before on one slice; nothing to colour when nothing changed."""
    lo, hi = grid.origin_m, grid.origin_m + grid.voxel_m * np.array(grid.shape)
    limit = float(np.max(np.abs(delta)))
    if limit == 0:
        ax.text(0.5, 0.5, "no change", ha="center", va="center", transform=ax.transAxes)
        ax.set_xlim(lo[a], hi[a])
        ax.set_ylim(lo[b], hi[b])
        ax.set_aspect("equal")
        return
    image = ax.imshow(
        delta.T,
        origin="lower",
        extent=(lo[a], hi[a], lo[b], hi[b]),
        cmap="coolwarm",
        vmin=-limit,
        vmax=limit,
        interpolation="nearest",
    )
    plt.colorbar(image, ax=ax, label="G after - before [m]", shrink=0.8)
    ax.set_aspect("equal")


def _support_level(trace: RunTrace) -> float:
    heights = [trace.track(s)[1][:, 2] for s in trace.supports]
    heights = [h for h in heights if len(h)]
    return float(np.median(np.concatenate(heights))) if heights else 7.5


def _zone_centre(world: World, level: float) -> np.ndarray:
    zones = world.scenario.world.zones
    if not zones:
        return np.full(3, level)
    return (np.array(zones[0].min_m) + np.array(zones[0].max_m)) / 2


def _legend_panel(ax, trace: RunTrace, marks: list[Mark]) -> None:
    """What every line, box and marker of the views is, how the run ended, and each mark."""
    ax.axis("off")
    handles = [
        Line2D([], [], color=COLORS.get(s, "k"), label=_label(s)) for s in [1, *trace.supports]
    ]
    handles += [
        Line2D([], [], color="magenta", lw=1.5, label="multipath zone"),
        Patch(facecolor="0.6", alpha=0.4, label="structure"),
        *legend_handles(marks, line=False),
    ]
    ax.legend(handles=handles, loc="upper left", fontsize=10, frameon=False)
    done = "not completed" if trace.completion is None else f"completed at {trace.completion} s"
    lines = [done + (f"; stopped: {trace.stopped}" if trace.stopped else "")]
    lines += [f"t = {m.t:g} s  {m.text}" for m in marks[:MARKS_LISTED]]
    if len(marks) > MARKS_LISTED:
        lines.append(f"... and {len(marks) - MARKS_LISTED} more (summary.json)")
    ax.text(0, 0.02, "\n".join(lines), family="monospace", fontsize=9, va="bottom")


def _box3d(ax, lo: np.ndarray, hi: np.ndarray) -> None:
    corners = np.array(
        [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    )
    for i in range(8):
        for j in range(i + 1, 8):
            if np.count_nonzero(corners[i] != corners[j]) == 1:
                ax.plot(*corners[[i, j]].T, color="magenta", lw=1.5)


def _save(fig, path: Path) -> None:
    save_figure(fig, path)
