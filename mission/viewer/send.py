"""Frames and the scene into a Rerun recording, a column per entity (``send_columns``): one
call per entity and frame, whatever its number of rows."""

from __future__ import annotations

import numpy as np
import rerun as rr

from mission.viewer import frame as f
from mission.viewer.scene import Scene

_POINT_RADII = {  # a UAV's own is its body's (the scene's)
    "estimate": f.ESTIMATE_RADIUS_M,
    "gnss": f.FIX_RADIUS_M,
    "role": f.ROLE_RADIUS_M,
}
_SERIES = {  # scalar kind: its name in the legend
    "work_error": "work UAV error (m)",
    "beta": "beta",
    "solve_ms": "MPC solve (ms)",
    "zone_steps": "steps in a zone",
    "fused": "in S",
    "role": "role",
}


def send_scene(rec: rr.RecordingStream, scene: Scene) -> None:
    """The static entities: the structure, the zones, the workspace, the planned waypoints,
    and how each plotted series is named and coloured."""
    rec.log(
        "world/structure",
        rr.Mesh3D(
            vertex_positions=scene.vertices,
            triangle_indices=scene.triangles,
            albedo_factor=f.BRIDGE_COLOUR,
        ),
        static=True,
    )
    if scene.zones:
        mins = np.array([low for _, low, _ in scene.zones])
        sizes = np.array([high - low for _, low, high in scene.zones])
        labels = [name for name, _, _ in scene.zones]
        rec.log(
            "world/zones",
            rr.Boxes3D(
                mins=mins,
                sizes=sizes,
                labels=labels,
                colors=f.ZONE_COLOUR,
                radii=0.06,
                fill_mode=rr.components.FillMode.MajorWireframe,
            ),
            static=True,
        )
    _send_gnss_error(rec, scene)
    low, high = scene.workspace
    rec.log(
        "world/workspace",
        rr.Boxes3D(
            mins=[low],
            sizes=[high - low],
            colors=f.WORKSPACE_COLOUR,
            radii=0.03,
            fill_mode=rr.components.FillMode.MajorWireframe,
        ),
        static=True,
    )
    _send_wind(rec, scene)
    _send_plans(rec, scene)
    for name in scene.waypoints:
        colour = f.colour_of(name)
        for kind, label in _SERIES.items():
            if name != "work" and kind != "work_error":
                series = rr.SeriesLines(colors=colour, names=f"{name} {label}")
                rec.log(f.scalar_path(kind, name), series, static=True)
    series = rr.SeriesLines(colors=f.WORK_COLOUR, names=_SERIES["work_error"])
    rec.log(f.scalar_path("work_error"), series, static=True)


def _send_gnss_error(rec: rr.RecordingStream, scene: Scene) -> None:
    """The true GNSS error field (multipath from geometry) as voxels beside G."""
    if scene.gnss_error is None:
        return
    indices, values = scene.gnss_error
    rec.log(
        f.GNSS_ERROR_PATH,
        rr.VoxelGridMap(
            voxel_indices=indices.astype(np.int32).reshape(-1, 3),
            voxel_size=[scene.voxel_m] * 3,
            values=np.nan_to_num(values, nan=f.GNSS_ERROR_RANGE_M[1]).astype(np.float32),
            translation=scene.voxel_origin,
            value_range=f.GNSS_ERROR_RANGE_M,
            colormap="magma",
            opacity=0.25,
        ),
        static=True,
    )


def _send_plans(rec: rr.RecordingStream, scene: Scene) -> None:
    """Each vehicle's planned waypoints and route, and the supports' own inspection waypoints
    (in the inspecting colour)."""
    for name, points in scene.waypoints.items():
        if len(points):
            colour = f.colour_of(name)
            rec.log(f"plan/{name}", rr.Points3D(points, colors=colour, radii=0.1), static=True)
            rec.log(
                f"plan/{name}/route",
                rr.LineStrips3D([points], colors=colour, radii=0.02),
                static=True,
            )
    for name, points in scene.inspections.items():
        colour = f.ROLE_COLOURS["inspecting"]
        rec.log(
            f"plan/{name}/inspections", rr.Points3D(points, colors=colour, radii=0.15), static=True
        )


def _send_wind(rec: rr.RecordingStream, scene: Scene) -> None:
    """The free stream's arrow, from above the workspace's upwind top corner (none in still
    air)."""
    if not np.any(scene.wind):
        return
    low, high = scene.workspace
    origin = np.array([*np.where(scene.wind >= 0, low, high)[:2], high[2]])
    arrow = rr.Arrows3D(origins=[origin], vectors=[scene.wind], colors=f.WIND_COLOUR, radii=0.1)
    rec.log("world/wind", arrow, static=True)


def send_frame(rec: rr.RecordingStream, frame: f.Frame, scene: Scene) -> None:
    """A frame's rows, entity by entity."""
    for path, rows in frame.points.items():
        kind = path.split("/", 1)[0]
        radius = scene.body_radius_m if kind == "uav" else _POINT_RADII.get(kind, 0.3)
        radii = rows.radii or [radius] * len(rows.times)
        columns = rr.Points3D.columns(
            positions=np.array(rows.values, dtype=float).reshape(-1, 3),
            colors=np.array(rows.colours, dtype=np.uint8).reshape(-1, 3),
            radii=np.array(radii, dtype=np.float32),
        ).partition(np.ones(len(rows.times), dtype=np.int32))
        _send(rec, path, rows.times, columns)
    for path, rows in frame.spheres.items():
        half = np.repeat(np.array(rows.radii, dtype=np.float32)[:, None], 3, axis=1)
        columns = rr.Ellipsoids3D.columns(
            centers=np.array(rows.values, dtype=float).reshape(-1, 3),
            half_sizes=half,
            colors=np.array(rows.colours, dtype=np.uint8).reshape(-1, 3),
            fill_mode=[rr.components.FillMode.MajorWireframe] * len(rows.times),
        ).partition(np.ones(len(rows.times), dtype=np.int32))
        _send(rec, path, rows.times, columns)
    for path, rows in frame.strips.items():
        radius = 0.05 if path.startswith(("mpc/", "safety/")) else 0.025
        columns = rr.LineStrips3D.columns(
            strips=[np.asarray(strip, dtype=float) for strip in rows.values],
            colors=np.array(rows.colours, dtype=np.uint8).reshape(-1, 3),
            radii=np.full(len(rows.times), radius, dtype=np.float32),
        ).partition(np.ones(len(rows.times), dtype=np.int32))
        _send(rec, path, rows.times, columns)
    for path, rows in frame.scalars.items():
        columns = rr.Scalars.columns(scalars=np.array(rows.values, dtype=float))
        _send(rec, path, rows.times, columns)
    for row in frame.voxels:
        rec.set_time(f.TIMELINE, duration=row.time_s)
        rec.log(
            f.G_PATH,
            rr.VoxelGridMap(
                voxel_indices=row.indices.astype(np.int32).reshape(-1, 3),
                voxel_size=[scene.voxel_m] * 3,
                values=row.values.astype(np.float32),
                translation=scene.voxel_origin,
                value_range=f.G_RANGE_M,
                colormap="turbo",
                opacity=0.35,
            ),
        )
        rec.reset_time()


def _send(rec: rr.RecordingStream, path: str, times: list[float], columns) -> None:
    index = rr.TimeColumn(f.TIMELINE, duration=np.array(times, dtype=float))
    rec.send_columns(path, indexes=[index], columns=columns)
