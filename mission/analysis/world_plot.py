"""A picture of a scenario's world: structure, zones, sky plot and sigma_0 slices."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import PolyCollection
from matplotlib.patches import Rectangle

from mission.analysis.figures import save_figure
from mission.world.model import Sigma0Map, World


def plot_world(world: World, point: np.ndarray, path: Path) -> None:
    """Draw top/side/cross-section views with sigma_0 and a sky plot at ``point``."""
    point = np.asarray(point, dtype=float)
    sigma0 = world.sigma0_map()
    fig = plt.figure(figsize=(14, 10))
    views = [
        (0, 1, 2, "top view (x-y)"),
        (0, 2, 1, "side view (x-z)"),
        (1, 2, 0, "cross-section (y-z)"),
    ]
    for slot, (a, b, normal, title) in zip((1, 2, 3), views):
        ax = fig.add_subplot(2, 2, slot)
        _draw_slice(ax, world, sigma0, point, a, b, normal, title)
    _draw_sky(fig.add_subplot(2, 2, 4, projection="polar"), world, point)
    fig.suptitle(
        f"scenario '{world.scenario.name}': sigma_0 = sqrt(tr Sigma_GNSS) and sky at "
        f"({point[0]:g}, {point[1]:g}, {point[2]:g}) m"
    )
    fig.tight_layout()
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
    """sigma_0 slice through ``point`` (axes a, b), the structure and the zones; the slice index."""
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
    for zone in world.scenario.world.zones:
        ax.add_patch(
            Rectangle(
                (zone.min_m[a], zone.min_m[b]),
                zone.max_m[a] - zone.min_m[a],
                zone.max_m[b] - zone.min_m[b],
                fill=False,
                edgecolor="magenta",
                linewidth=2,
                label=f"zone {zone.name}",
            )
        )
    return k


def _draw_slice(
    ax, world: World, sigma0: Sigma0Map, point, a: int, b: int, normal: int, title: str
) -> None:
    grid = sigma0.grid
    k = draw_background(ax, world, sigma0, point, a, b, normal)
    ax.plot(point[a], point[b], "k*", markersize=12, label="sky-plot point")
    axis = "xyz"
    ax.set_xlabel(f"{axis[a]} [m]")
    ax.set_ylabel(f"{axis[b]} [m]")
    ax.set_title(f"{title}, slice {axis[normal]} = {grid.axis_centers(normal)[k]:g} m")
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
