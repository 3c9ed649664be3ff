"""Top and side views of a plan: bridge, zones, sigma_0, work and support paths (Figs. 4-5)."""

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

COLORS = ("tab:blue", "tab:green", "tab:purple", "tab:olive", "tab:cyan")


def plot_plan(world: World, plan: Plan, path: Path) -> None:
    """Write a two-panel PNG of the plan."""
    sigma0 = world.sigma0_map()
    fig, axes = plt.subplots(2, 1, figsize=(12, 11))
    for ax, (a, b, normal, title) in zip(axes, ((0, 1, 2, "top view"), (0, 2, 1, "side view"))):
        level = float(np.mean(plan.supports[:, :, normal]))
        k = int(sigma0.grid.index_of(np.full((1, 3), level))[0, normal])
        point = np.full(3, level)
        draw_background(ax, world, sigma0, point, a, b, normal, alpha=0.6)
        _path(ax, plan.work, a, b, "tab:red", "work UAV")
        for n, points in enumerate(plan.supports):
            _path(ax, points, a, b, COLORS[n % len(COLORS)], f"support {n + 1}")
        axis = "xyz"
        ax.set_title(
            f"{title}, sigma_0 at {axis[normal]} = {sigma0.grid.axis_centers(normal)[k]:g} m"
        )
        ax.set_xlabel(f"{axis[a]} [m]")
        ax.set_ylabel(f"{axis[b]} [m]")
        ax.set_aspect("equal")
        ax.legend(loc="upper right", fontsize=7)
    fig.suptitle(f"plan of scenario '{world.scenario.name}' (numbers: waypoint index)")
    fig.tight_layout()
    save_figure(fig, path)


def _path(ax, points: np.ndarray, a: int, b: int, color: str, label: str) -> None:
    ax.plot(points[:, a], points[:, b], "-o", color=color, markersize=4, label=label)
    for i, point in enumerate(points, start=1):
        ax.annotate(
            str(i),
            (point[a], point[b]),
            fontsize=7,
            color=color,
            xytext=(3, 3),
            textcoords="offset points",
        )
