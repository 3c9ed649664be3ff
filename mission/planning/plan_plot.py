"""Top and side views of a plan: bridge, zones, sigma_0, work and support paths (Figs. 4-5).

A side view shows sigma_0 on one slice of y, so each is drawn for the vehicles that fly near
that slice: one side view per slice the vehicles' paths lie in (a support beside the deck is
not drawn over the no-fix region under it), a waypoint off the slice hollow."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np

from mission.analysis.figures import save_figure
from mission.analysis.world_plot import draw_background
from mission.link.plan_files import Plan
from mission.world.model import World

WORK_COLOR = "tab:red"
SUPPORT_COLORS = ("tab:blue", "tab:green", "tab:purple", "tab:olive", "tab:cyan")
AXES = "xyz"
OFF_SLICE_M = 1.0  # a waypoint further than this from a side view's slice is drawn hollow


def side_view_groups(world: World, plan: Plan) -> list[tuple[float, list[int]]]:
    """(y of the sigma_0 slice, the vehicles drawn over it) per side view, by y: each vehicle
    (0 the work UAV, n support n) over the slice most of its waypoints lie in (of equally
    many, the one nearest their median y)."""
    grid = world.sigma0_map().grid
    centres = grid.axis_centers(1)
    groups: dict[int, list[int]] = {}
    for vehicle, points in enumerate([plan.work, *plan.supports]):
        slices, counts = np.unique(grid.index_of(points)[:, 1], return_counts=True)
        middle = float(np.median(points[:, 1]))
        best = max(zip(slices, counts), key=lambda sc: (sc[1], -abs(centres[sc[0]] - middle)))[0]
        groups.setdefault(int(best), []).append(vehicle)
    return [(float(centres[k]), groups[k]) for k in sorted(groups)]


def plot_plan(world: World, plan: Plan, path: Path) -> None:
    """Write the plan's figure: a top view, and a side view per slice of y its paths lie in."""
    sigma0 = world.sigma0_map()
    groups = side_view_groups(world, plan)
    fig, axes = plt.subplots(
        1 + len(groups),
        1,
        figsize=(11, 6.6 + 3.4 * len(groups)),
        gridspec_kw={"height_ratios": [6.2] + [3.4] * len(groups)},
        squeeze=False,
        layout="constrained",
    )
    level = float(np.mean(plan.supports[:, :, 2]))
    k = draw_background(axes[0, 0], world, sigma0, np.full(3, level), 0, 1, 2, alpha=0.6)
    height = sigma0.grid.axis_centers(2)[k]
    everyone = list(range(1 + len(plan.supports)))
    _paths(axes[0, 0], plan, everyone, 0, 1, (2, height))
    _finish(axes[0, 0], f"top view, sigma_0 at z = {height:g} m (the supports' mean height)")
    for ax, (y, vehicles) in zip(axes[1:, 0], groups):
        draw_background(ax, world, sigma0, np.array([0.0, y, 0.0]), 0, 2, 1, alpha=0.6)
        _paths(ax, plan, vehicles, 0, 2, (1, y))
        names = " and ".join(_name(v) for v in vehicles)
        whose = "its" if len(vehicles) == 1 else "their"
        _finish(ax, f"side view of {names}: sigma_0 at y = {y:g} m (most of {whose} waypoints)")
    fig.suptitle(f"plan of scenario '{world.scenario.name}' (numbers: waypoint index)")
    save_figure(fig, path)


def _name(vehicle: int) -> str:
    return "work UAV" if vehicle == 0 else f"support {vehicle}"


def _paths(ax, plan: Plan, vehicles: list[int], a: int, b: int, cut: tuple[int, float]) -> None:
    """The vehicles' paths over the slice ``cut`` (its axis, where), waypoints off it hollow."""
    normal, at = cut
    hollow = False
    for vehicle in vehicles:
        points = plan.work if vehicle == 0 else plan.supports[vehicle - 1]
        color = WORK_COLOR if vehicle == 0 else SUPPORT_COLORS[(vehicle - 1) % len(SUPPORT_COLORS)]
        off = np.abs(points[:, normal] - at) > OFF_SLICE_M
        _path(ax, points, a, b, color, _name(vehicle), off)
        hollow |= bool(off.any())
    if hollow:
        label = f"hollow: a waypoint > {OFF_SLICE_M:g} m off this slice"
        ax.plot([], [], "o", color="0.3", mfc="white", label=label)


def _finish(ax, title: str) -> None:
    ax.set_title(title, fontsize=11)
    a, b = ("x", "y") if "top view" in title else ("x", "z")
    ax.set_xlabel(f"{a} [m]")
    ax.set_ylabel(f"{b} [m]")
    ax.set_aspect("equal")
    ax.legend(loc="upper right", fontsize=7)


def _path(ax, points: np.ndarray, a: int, b: int, color: str, label: str, off) -> None:
    """A path, its waypoints off the slice hollow under those on it (a side view can stack
    them)."""
    ax.plot(points[:, a], points[:, b], "-", color=color)
    ax.plot(points[off, a], points[off, b], "o", color=color, mfc="white", markersize=5)
    ax.plot(points[~off, a], points[~off, b], "o", color=color, markersize=4)
    ax.plot([], [], "-o", color=color, markersize=4, label=label)
    for i, point in enumerate(points, start=1):
        ax.annotate(
            str(i),
            (point[a], point[b]),
            fontsize=7,
            color=color,
            xytext=(3, 3),
            textcoords="offset points",
        )
