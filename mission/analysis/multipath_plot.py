"""``mission world --multipath-map``: the GNSS error that reflections off the structure and the
ground make (:mod:`mission.world.multipath`), without noise: horizontal and vertical error on
slices at the mission's heights, the structure over them, and the sky at the worst point with
its worst satellites named."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import PolyCollection

from mission.analysis.figures import save_figure
from mission.config.errors import InputError
from mission.link.plan_files import read_vehicle_waypoints, vehicle_names
from mission.world.model import World
from mission.world.multipath import GeometricReceiver, ReceiverSolution
from mission.world.surfaces import NONE_ABOVE_M, VerticalSurfaces

STEP_M = 0.5  # the slices' resolution
MAX_HEIGHTS = 3
WORST_NAMED = 4
ERROR_SCALE_M = (0.1, 30.0)  # log colour scale; smaller errors (an RTK fix's 0) at its floor


def receiver_of(world: World) -> GeometricReceiver:
    """The scenario's receiver, or (its multipath from zones) one with its signal settings."""
    if world.receiver is not None:
        return world.receiver
    signal = dataclasses.replace(world.scenario.world.gnss, multipath="geometry")
    return GeometricReceiver(world.gnss, signal, world.scenario.source)


def mission_heights(world: World) -> list[float]:
    """The heights the supports' planned waypoints fly at, the most used first (at most
    MAX_HEIGHTS), or the work UAV's where there is no plan."""
    scenario = world.scenario
    heights: list[float] = []
    try:
        for name in vehicle_names(scenario.task.supports)[1:]:
            heights += [round(float(z), 2) for z in read_vehicle_waypoints(scenario, name)[:, 2]]
    except InputError:  # no plan (yet): the work UAV's heights
        heights = []
    if not heights:
        heights = [round(float(p[2]), 2) for p in scenario.task.work_waypoints_m]
    values, counts = np.unique(heights, return_counts=True)
    ranked = values[np.argsort(-counts, kind="stable")][:MAX_HEIGHTS]
    return sorted(float(h) for h in ranked)


def plot_multipath(world: World, path: Path) -> dict:
    """Draw the map to ``path``; returns the worst error found and where, and per height
    the error's spread under the structure and in the open (:func:`region_lines`)."""
    receiver = receiver_of(world)
    heights = mission_heights(world)
    space = world.scenario.world.workspace
    xs = np.arange(space.min_m[0] + STEP_M / 2, space.max_m[0], STEP_M)
    ys = np.arange(space.min_m[1] + STEP_M / 2, space.max_m[1], STEP_M)
    grid_x, grid_y = np.meshgrid(xs, ys, indexing="ij")
    fig, axes = plt.subplots(
        len(heights) + 1, 2, figsize=(12, 3.6 * (len(heights) + 1)), squeeze=False
    )
    worst = (-1.0, np.zeros(3))
    regions = []
    surfaces = VerticalSurfaces(world.structure)
    for row, z in enumerate(heights):
        points = np.column_stack((grid_x.ravel(), grid_y.ravel(), np.full(grid_x.size, z)))
        inside = world.structure.contains(points)
        solution = receiver.solve(points)
        error = solution.position_error_m
        horizontal = np.hypot(error[:, 0], error[:, 1])
        vertical = np.abs(error[:, 2])
        total = np.where(inside, -1.0, np.nan_to_num(np.hypot(horizontal, vertical), nan=-1))
        if total.max() > worst[0]:
            worst = (float(total.max()), points[int(np.argmax(total))])
        covered = surfaces.heights(points)[0] < NONE_ABOVE_M
        outside = ~inside
        regions.append(
            (z, _spread(solution, outside & covered), _spread(solution, outside & ~covered))
        )
        for column, (values, what) in enumerate(
            ((horizontal, "horizontal"), (vertical, "vertical"))
        ):
            shown = np.where(inside | ~solution.has_fix, np.nan, values)
            shown = np.maximum(shown, ERROR_SCALE_M[0]).reshape(grid_x.shape)
            _slice(axes[row, column], world, xs, ys, shown, f"{what} error at z = {z:g} m")
    _sky(axes[-1, 0], world, receiver, worst[1])
    _legend_panel(axes[-1, 1], world, receiver)
    fig.suptitle(
        f"'{world.scenario.name}': GNSS error from reflections "
        f"({world.scenario.world.gnss.solution} receiver, no noise)",
        y=0.995,
    )
    fig.tight_layout()
    save_figure(fig, path, dpi=100)
    where = {"x": worst[1][0], "y": worst[1][1], "z": worst[1][2]}
    return {"worst_m": round(worst[0], 3), **where, "regions": regions}


def _spread(solution: ReceiverSolution, where: np.ndarray) -> dict | None:
    """Of the points ``where``: the share with a fix, the share not carrier-fixed, and the
    median, p95 and max of the error where there is a fix."""
    if not where.any():
        return None
    fixed = solution.has_fix & where
    error = np.linalg.norm(solution.position_error_m[fixed], axis=1)
    spread = [float(np.percentile(error, q)) for q in (50, 95, 100)] if len(error) else None
    floating = float((fixed & ~solution.carrier_fixed).sum() / max(int(fixed.sum()), 1))
    return {"fix": float(fixed.sum() / where.sum()), "float": floating, "error_m": spread}


def region_lines(regions: list) -> list[str]:
    """One line per height and region: under the structure, and in the open."""
    lines = []
    for z, *parts in regions:
        for name, part in zip(("under the structure", "in the open"), parts):
            if part is None:
                continue
            said = (
                "no fix"
                if part["error_m"] is None
                else ("error median {:.2f}, p95 {:.2f}, max {:.2f} m".format(*part["error_m"]))
            )
            lines.append(
                f"  z = {z:g} m, {name}: fix {part['fix']:.0%}, not carrier-fixed "
                f"{part['float']:.0%}, {said}"
            )
    return lines


def _slice(ax, world: World, xs, ys, values: np.ndarray, title: str) -> None:
    image = ax.imshow(
        values.T,
        origin="lower",
        extent=(xs[0] - STEP_M / 2, xs[-1] + STEP_M / 2, ys[0] - STEP_M / 2, ys[-1] + STEP_M / 2),
        cmap="magma_r",
        norm=matplotlib.colors.LogNorm(*ERROR_SCALE_M),
        interpolation="nearest",
    )
    plt.colorbar(image, ax=ax, label="error [m] (white: no fix or inside)", shrink=0.85)
    triangles = world.structure.mesh.triangles[:, :, [0, 1]]
    ax.add_collection(PolyCollection(triangles, facecolor="0.5", edgecolor="none", alpha=0.15))
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title, fontsize=10)
    ax.set_aspect("equal")


def _sky(ax_slot, world: World, receiver: GeometricReceiver, point: np.ndarray) -> None:
    """The sky at ``point``: each satellite direct, tracked on a reflection, or lost; the
    largest range errors named."""
    fig = ax_slot.figure
    spec = ax_slot.get_subplotspec()
    ax_slot.remove()
    ax = fig.add_subplot(spec, projection="polar")
    solution: ReceiverSolution = receiver.solve(point[None])
    sky = world.sky
    zenith = 90 - np.degrees(sky.elevation_rad)
    tracked, reflected = solution.tracked[0], solution.reflected[0]
    groups = (
        (tracked & ~reflected, dict(color="tab:green", marker="o"), "direct"),
        (reflected, dict(color="tab:red", marker="s"), "reflection only (NLOS)"),
        (sky.above_mask & ~tracked, dict(color="0.5", marker="x"), "lost"),
    )
    for mask, style, label in groups:
        ax.scatter(sky.azimuth_rad[mask], zenith[mask], s=50, label=label, **style)
    error = solution.range_error_m[0]
    for index in np.argsort(-np.abs(error))[:WORST_NAMED]:
        if abs(error[index]) > 0.01:
            ax.annotate(
                f"{sky.sv[index]} {error[index]:+.1f} m",
                (sky.azimuth_rad[index], zenith[index]),
                fontsize=8,
                xytext=(5, 5),
                textcoords="offset points",
            )
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    ax.set_rlim(0, 90)
    ax.set_yticks([0, 30, 60, 90], labels=["90", "60", "30", "0"])
    fix = solution.position_error_m[0]
    said = (
        "no fix"
        if not solution.has_fix[0]
        else f"error ({fix[0]:+.1f}, {fix[1]:+.1f}, {fix[2]:+.1f}) m"
    )
    ax.set_title(
        f"sky at the worst point ({point[0]:g}, {point[1]:g}, {point[2]:g}): {said}",
        fontsize=9,
        pad=14,
    )
    ax.legend(loc="upper left", bbox_to_anchor=(1.05, 1.0), fontsize=8)


def _legend_panel(ax, world: World, receiver: GeometricReceiver) -> None:
    signal = receiver.signal
    ax.axis("off")
    lines = [
        f"multipath model: {world.scenario.world.gnss.multipath}",
        f"structure: {signal.structure_surface} "
        f"({signal.amplitude.of(signal.structure_surface):g}); ground: "
        f"{signal.ground_surface} ({signal.amplitude.of(signal.ground_surface):g})",
        f"correlator spacing {signal.correlator_spacing_chips:g} chip; C/N0 "
        f"{signal.cn0_open_sky_dbhz:g} dB-Hz open sky, floor {signal.cn0_floor_dbhz:g}",
        f"antenna {signal.antenna_below_horizon_db:g} dB from below its horizon",
        "",
        "errors are the fix's without noise (sigma_UERE adds to them);",
        "an RTK receiver's are zero while it tracks no reflection",
    ]
    ax.text(0.0, 0.95, "\n".join(lines), va="top", fontsize=9, family="monospace")
