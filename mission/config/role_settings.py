"""Who does what (the paper's third open question): the work UAV on its own GNSS
where it can (:mod:`ground_station.roles`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from mission.config.checks import positive as _positive
from mission.config.checks import require as _require


@dataclass(frozen=True)
class RoleSettings:
    """``policy: fixed`` (the paper): the work UAV is localized by the supports alone, its own
    GNSS fix ignored. ``dynamic``: the ground station also judges the work UAV's own fix each
    cycle and fuses it when it is trustworthy: a 3-D fix where the map G (learned, or the sky's
    prediction) expects at most ``own_fix_max_sigma_m``, and, where the supports give a
    relative estimate, within ``own_fix_agreement_sigmas`` standard deviations of it.

    With ``dynamic`` the supports also inspect for themselves when the formation can spare
    them (:mod:`ground_station.roles.allocation`): all but ``keep_in_formation`` are released
    once the work UAV's own fix is expected trustworthy along its path for at least
    ``release_clear_s`` of its flight, and recalled once it is expected for less than
    ``recall_clear_s`` (the hysteresis: release needs the longer look ahead). A released
    support has reached an inspection waypoint within ``inspection_tol_m``. With ``fixed``,
    the supports fly their inspections once the work UAV's task is complete."""

    policy: Literal["fixed", "dynamic"]
    own_fix_max_sigma_m: float
    own_fix_agreement_sigmas: float
    release_clear_s: float
    recall_clear_s: float
    keep_in_formation: int
    inspection_tol_m: float

    def __post_init__(self) -> None:
        _positive(
            self,
            "own_fix_max_sigma_m",
            "own_fix_agreement_sigmas",
            "release_clear_s",
            "recall_clear_s",
            "inspection_tol_m",
        )
        for name in ("release_clear_s", "recall_clear_s", "inspection_tol_m"):
            _require(math.isfinite(getattr(self, name)), name, "must be finite")
        _require(
            self.release_clear_s > self.recall_clear_s,
            "release_clear_s",
            f"{self.release_clear_s:g} s must exceed recall_clear_s ({self.recall_clear_s:g} s): "
            "the hysteresis is the wrong way round (a support would be recalled as soon as it "
            "is released)",
        )
        _require(self.keep_in_formation >= 0, "keep_in_formation", "must be >= 0")


@dataclass(frozen=True)
class Inspection:
    """What a support would photograph when the formation frees it: its own inspection
    waypoints (ENU, m), flown in order."""

    vehicle: str  # support-N
    waypoints_m: list[tuple[float, float, float]]

    def __post_init__(self) -> None:
        _require(bool(self.waypoints_m), "waypoints_m", "needs at least one waypoint")


def check_roles(roles: RoleSettings, supports: int, arrival_tol_m: float) -> None:
    """The formation kept while supports inspect has no more supports than the scenario; an
    inspection waypoint's tolerance is no tighter than the work UAV's arrival's
    (control.arrival_tol_m), or a support's noisy fix would seldom if ever come that close."""
    _require(
        roles.keep_in_formation <= supports,
        "roles.keep_in_formation",
        f"{roles.keep_in_formation} is more than the scenario's {supports} supports",
    )
    tolerance = roles.inspection_tol_m
    _require(
        tolerance >= arrival_tol_m,
        "roles.inspection_tol_m",
        f"{tolerance:g} m is less than control.arrival_tol_m ({arrival_tol_m:g} m): a "
        "support's noisy fix would seldom if ever come that close",
    )


def check_waypoints(task, workspace, ground_clearance_m: float) -> None:
    """The work UAV's waypoints and the supports' inspections (:func:`check_inspections`):
    every waypoint inside the workspace and at least ``ground_clearance_m`` (the safety
    clearance, control.clearance_m) above the ground, which no flight could keep below it."""
    for i, point in enumerate(task.work_waypoints_m):
        _check_point(point, f"task.work_waypoints_m[{i}]", workspace, ground_clearance_m)
    check_inspections(task.inspections, task.supports, workspace, ground_clearance_m)


def _check_point(point, where: str, workspace, ground_clearance_m: float) -> None:
    inside = all(workspace.min_m[a] <= point[a] <= workspace.max_m[a] for a in range(3))
    _require(inside, where, f"{list(point)} lies outside the workspace")
    _require(
        point[2] >= ground_clearance_m,
        where,
        f"{list(point)} is {point[2]:g} m above the ground, less than control.clearance_m "
        f"({ground_clearance_m:g} m)",
    )


def check_inspections(
    inspections: list[Inspection], supports: int, workspace, ground_clearance_m: float
) -> None:
    """Each entry names a support of the scenario, once, and every waypoint lies inside the
    workspace and ``ground_clearance_m`` above the ground (inside the structure is checked
    with the world, before a run starts)."""
    seen: set[str] = set()
    names = {f"support-{n}" for n in range(1, supports + 1)}
    for i, inspection in enumerate(inspections):
        where = f"task.inspections[{i}]"
        _require(
            inspection.vehicle in names,
            f"{where}.vehicle",
            f"{inspection.vehicle!r} is not a support of this scenario (support-1..{supports})",
        )
        _require(inspection.vehicle not in seen, f"{where}.vehicle", "is listed twice")
        seen.add(inspection.vehicle)
        for j, point in enumerate(inspection.waypoints_m):
            _check_point(point, f"{where}.waypoints_m[{j}]", workspace, ground_clearance_m)
