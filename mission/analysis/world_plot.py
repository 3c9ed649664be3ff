"""A picture of a scenario's world: structure, zones, sky plot and sigma_0 slices (top views
at the heights the structure and the task make worth seeing: :mod:`slice_heights`)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import PolyCollection
from matplotlib.patches import Rectangle

from mission.analysis.figures import save_figure
from mission.analysis.slice_heights import slice_heights
from mission.world.model import Sigma0Map, World


def plot_world(world: World, point: np.ndarray, path: Path) -> None:
    """Draw top views at the structure's and the task's heights, side and cross-section
    views through ``point``, each with sigma_0, and the sky plot at ``point``."""
    point = np.asarray(point, dtype=float)
    sigma0 = world.sigma0_map()
    heights = slice_heights(world)
    rows = -(-(len(heights) + 3) // 2)
    fig = plt.figure(figsize=(14, 4.9 * rows), layout="constrained")
    slot = 0
    for height in heights:
        slot += 1
        at = np.array([point[0], point[1], height.z_m])
        ax = fig.add_subplot(rows, 2, slot)
        _draw_slice(ax, world, sigma0, at, point, (0, 1, 2), ("top view (x-y)", height.why))
    for a, b, normal, title in ((0, 2, 1, "side view (x-z)"), (1, 2, 0, "cross-section (y-z)")):
        slot += 1
        ax = fig.add_subplot(rows, 2, slot)
        why = "through the sky-plot point"
        _draw_slice(ax, world, sigma0, point, point, (a, b, normal), (title, why))
    _draw_sky(fig.add_subplot(rows, 2, slot + 1, projection="polar"), world, point)
    fig.suptitle(
        f"scenario '{world.scenario.name}': sigma_0 = sqrt(tr Sigma_GNSS) and sky at "
        f"({point[0]:g}, {point[1]:g}, {point[2]:g}) m"
    )
    save_figure(fig, path, dpi=110)


def draw_background(
    ax,
    world: World,
    sigma0: Sigma0Map,
    point: np.ndarray,
    a: int,
    b: int,
    normal: int,
    alpha: float = 1.0,
    label: str = "sigma_0 [m]",
) -> int:
    """sigma_0 slice through ``point`` (axes a, b), the structure and the zones (dashed: a
    zone the slice does not pass through); the slice index."""
    grid = sigma0.grid
    k = int(grid.index_of(np.asarray(point)[None])[0, normal])
    values = np.take(sigma0.sigma_m, k, axis=normal)
    if a > b:
        values = values.T
    lo, hi = grid.origin_m, grid.origin_m + grid.voxel_m * np.array(grid.shape)
    image = ax.imshow(
        values.T,
        origin="lower",
        extent=(lo[a], hi[a], lo[b], hi[b]),
        cmap="RdYlGn_r",
        norm=matplotlib.colors.LogNorm(vmin=0.1, vmax=world.scenario.map.no_fix_sigma_m),
        interpolation="nearest",
        alpha=alpha,
    )
    plt.colorbar(image, ax=ax, label=label, shrink=0.8)
    triangles = world.structure.mesh.triangles[:, :, [a, b]]
    ax.add_collection(PolyCollection(triangles, facecolor="0.55", edgecolor="none", alpha=0.25))
    at = grid.axis_centers(normal)[k]
    for zone in world.scenario.world.zones:
        cut = zone.min_m[normal] <= at <= zone.max_m[normal]  # does the slice pass through it
        ax.add_patch(
            Rectangle(
                (zone.min_m[a], zone.min_m[b]),
                zone.max_m[a] - zone.min_m[a],
                zone.max_m[b] - zone.min_m[b],
                fill=False,
                edgecolor="magenta",
                linewidth=2,
                linestyle="-" if cut else "--",
                label=f"zone {zone.name}" + ("" if cut else " (off this slice)"),
            )
        )
    return k


def _draw_slice(
    ax, world: World, sigma0: Sigma0Map, at, star, axes: tuple[int, int, int], title: tuple
) -> None:
    """sigma_0 on the slice through ``at`` of the view ``axes`` (a, b, normal), titled (what
    view, why this slice) with the layer's bounds; the sky plot's point ``star``."""
    a, b, normal = axes
    grid = sigma0.grid
    k = draw_background(ax, world, sigma0, at, a, b, normal)
    ax.plot(star[a], star[b], "k*", markersize=12, label=f"sky-plot point (z = {star[2]:g} m)")
    axis = "xyz"
    low = grid.origin_m[normal] + grid.voxel_m * k
    layer = f"{axis[normal]} = {low:g} to {low + grid.voxel_m:g} m"
    ax.set_xlabel(f"{axis[a]} [m]")
    ax.set_ylabel(f"{axis[b]} [m]")
    view, why = title
    ax.set_title(f"{view} at {layer}: {why}", fontsize=10)
    ax.set_aspect("equal")
    ax.legend(loc="upper right", fontsize=7)


def _draw_sky(ax, world: World, point) -> None:
    sky = world.sky
    visible = world.gnss.visibility(point[None])[0]
    zenith = 90 - np.degrees(sky.elevation_rad)
    for mask, style, label in (
        (visible, dict(color="tab:green", marker="o"), "visible"),
        (sky.above_mask & ~visible, dict(color="tab:red", marker="x"), "blocked by structure"),
        (~sky.above_mask, dict(color="0.6", marker="."), "below mask"),
    ):
        ax.scatter(sky.azimuth_rad[mask], zenith[mask], s=60, label=label, **style)
    for az, zen, sv in zip(sky.azimuth_rad, zenith, sky.sv):
        ax.annotate(sv, (az, zen), fontsize=7, xytext=(4, 4), textcoords="offset points")
    mask_zenith = 90 - world.scenario.sky.elevation_mask_deg
    theta = np.linspace(0, 2 * np.pi, 200)
    ax.plot(theta, np.full_like(theta, mask_zenith), "k--", linewidth=0.8)
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    ax.set_rlim(0, 90)
    ax.set_yticks([0, 30, 60, 90], labels=["90", "60", "30", "0"])
    geometry = world.gnss.geometry(point[None])
    pdop = f"{geometry.pdop[0]:.2f}" if geometry.has_fix[0] else "no fix"
    ax.set_title(
        f"sky plot ({world.scenario.sky.epoch_utc}): {int(visible.sum())} visible, PDOP {pdop}"
    )
    ax.legend(loc="lower left", bbox_to_anchor=(-0.25, -0.12), fontsize=8)
