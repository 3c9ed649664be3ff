"""Text and JSON views of a scenario's world for ``python -m mission world``."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from mission.world.model import World


def point_report(world: World, point: np.ndarray) -> dict[str, Any]:
    """GNSS facts at one ENU point: visible satellites, PDOP, sqrt(tr Sigma_GNSS), zone."""
    point = np.asarray(point, dtype=float).reshape(1, 3)
    geometry = world.gnss.geometry(point)
    visible = [sv for sv, seen in zip(world.sky.sv, geometry.visible[0]) if seen]
    fixed = bool(geometry.has_fix[0])
    pdop = float(geometry.pdop[0]) if fixed else None
    report = {
        "visible": visible,
        "n_visible": len(visible),
        "pdop": _rounded(pdop),
        "sigma_gnss_m": _rounded(world.scenario.gnss.sigma_uere_m * pdop if fixed else None),
        "in_zone": bool(world.in_zone(point)[0]),
    }
    if world.receiver is not None:
        report["multipath"] = _receiver_report(world, point)
    return report


def _receiver_report(world: World, point: np.ndarray) -> dict[str, Any]:
    """What the geometry's receiver makes of the sky at ``point`` (no noise)."""
    solution = world.receiver.solve(point)
    sv = world.sky.sv
    fixed = bool(solution.has_fix[0])
    error = solution.range_error_m[0]
    return {
        "used": [s for s, used in zip(sv, solution.tracked[0]) if used],
        "reflected": [s for s, nlos in zip(sv, solution.reflected[0]) if nlos],
        "range_error_m": {s: round(float(e), 3) for s, e in zip(sv, error) if e != 0},
        "solution": _solution_name(world, bool(solution.carrier_fixed[0])) if fixed else None,
        "error_m": [round(float(v), 3) for v in solution.position_error_m[0]] if fixed else None,
    }


def _solution_name(world: World, carrier_fixed: bool) -> str:
    if carrier_fixed:
        return "rtk-fixed"
    return "rtk-float" if world.scenario.world.gnss.solution == "rtk" else "code"


def summary_text(world: World) -> str:
    """A readable multi-line summary of the scenario and its world."""
    scn = world.scenario
    w = scn.world
    lines = [
        f"scenario   {scn.name}: {scn.description}",
        f"source     {scn.source}",
        f"anchor     {w.anchor.lat_deg:.6f} N, {w.anchor.lon_deg:.6f} E, {w.anchor.alt_m:.1f} m",
        "workspace  " + "  ".join(f"{'xyz'[a]} {_span(w.workspace, a)}" for a in range(3)) + " m",
        f"structure  {len(w.structure.primitives)} primitives"
        + (f" + mesh {w.structure.mesh_file}" if w.structure.mesh_file else "")
        + f", {len(world.structure.faces)} triangles, ray engine "
        + ("Embree" if world.structure.uses_embree else "trimesh (no Embree)"),
    ]
    lines += [f"  {p.name:<10} {p.min_m} .. {p.max_m}" for p in w.structure.primitives]
    lines.append(f"zones      {len(w.zones)} (known to the vehicles only)")
    lines.append(
        f"multipath  {w.gnss.multipath} (known to the vehicles only); structure "
        f"{w.gnss.structure_surface}, ground {w.gnss.ground_surface}, {w.gnss.solution} receiver"
    )
    lines += [f"  {z.name:<10} {z.min_m} .. {z.max_m}  offset {z.offset_m} m" for z in w.zones]
    sky = world.sky
    counts = {
        c: sum(1 for s, m in zip(sky.sv, sky.above_mask) if m and s[0] == c)
        for c in sky.constellations
    }
    open_sky = world.gnss.geometry_from_visibility(sky.above_mask[None].copy())
    pdop = float(open_sky.pdop[0]) if open_sky.has_fix[0] else math.nan
    lines += [
        f"sky        {scn.sky.epoch_utc}, mask {scn.sky.elevation_mask_deg:g} deg, "
        + ", ".join(f"{c}: {n}" for c, n in counts.items())
        + f" above mask, open-sky PDOP {pdop:.2f}",
        f"gnss       sigma_UERE {scn.gnss.sigma_uere_m:g} m, open-sky sqrt(tr Sigma) "
        f"{scn.gnss.sigma_uere_m * pdop:.3f} m",
        f"camera     sigma_d(10 m) {float(world.camera.sigma_d(10.0)):.3f} m, angles "
        f"{scn.camera.sigma_elevation_deg:g}/{scn.camera.sigma_azimuth_deg:g} deg, "
        f"range {scn.camera.range_m:g} m",
    ]
    sigma0 = world.sigma0_map()
    no_fix = int((~sigma0.has_fix).sum())
    lines += [
        f"map G      {sigma0.grid.shape} voxels of {scn.map.voxel_size_m:g} m "
        f"({sigma0.grid.n_voxels}), {no_fix} without fix (sigma_0 capped at "
        f"{scn.map.no_fix_sigma_m:g} m), built in {sigma0.build_s:.2f} s",
        f"control    t_cont {scn.control.t_cont_s:g} s, t_pred {scn.control.t_pred_s:g} s, "
        f"U {scn.control.horizon_steps}, s_max work/support {scn.control.s_max_work_m_s:g}/"
        f"{scn.control.s_max_support_m_s:g} m/s",
        f"run        timeout {scn.run.timeout_s:g} s (simulated)",
    ]
    return "\n".join(lines)


def _span(box: Any, axis: int) -> str:
    return f"[{box.min_m[axis]:g}, {box.max_m[axis]:g}]"


def _rounded(value: float | None) -> float | None:
    return None if value is None else round(value, 4)
