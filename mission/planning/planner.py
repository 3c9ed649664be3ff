"""Offline planning of the support UAVs' paths (docs/model.md, "Pre-planned support paths",
in place of the paper's [18]).

For each work waypoint w_i, every support gets a point of a lattice that is free (clear of the
structure and the ground), within camera range of w_i with a clear sight line and no closer to
it than the run's separation margin (``control.min_separation_m``), and has a GNSS fix. A
point costs

    w_gnss sigma_0(p)^2 + w_relative tr Sigma_r(w_i - p)     (the variance it adds to mu_n)
  + w_move |p - p_{i-1}|                                    (movement)
  + w_spread sum_m cos^2(angle between p and the other supports, seen from w_i)

subject to a minimum separation between supports and reachability at the support speed in the
time the work UAV needs between waypoints. Each support's path is found by dynamic programming
over i with the others held fixed; a few rounds of this coordinate descent settle the formation.
Everything is deterministic (stable sorts, first-index tie breaks, costs settled to 1e-12 so
that a tie stays a tie whatever the last bits of numpy's kernels).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mission.config.errors import InputError
from mission.link.plan_files import Plan
from mission.world.grid import VoxelGrid
from mission.world.model import KnownWorld

CANDIDATES_PER_INDEX = 1000
COST_DECIMALS = 12  # a plan cost's resolution, of costs of order 1-100 (their last bits ~1e-14)


class PlanningError(InputError):
    """The scenario's task cannot be planned; names the waypoint and the reason."""


@dataclass(frozen=True)
class _Candidates:
    points: np.ndarray  # (K, 3)
    base_cost: np.ndarray  # (K,)


def plan_supports(world: KnownWorld) -> Plan:
    """Plan every support's I waypoints for the scenario's work waypoints."""
    scenario = world.scenario
    work = np.array(scenario.task.work_waypoints_m, dtype=float)
    _check_work_waypoints(world, work)
    admissible = _admissible_points(world)
    candidates = [_candidates_for(world, admissible, w, i) for i, w in enumerate(work)]
    control = scenario.control
    leg = np.linalg.norm(np.diff(work, axis=0), axis=1)
    reach = control.s_max_support_m_s * leg / control.s_max_work_m_s + 1e-9
    legs_clear = [
        _legs_clear(world, candidates[i - 1].points, candidates[i].points)
        for i in range(1, len(work))
    ]
    n_supports = scenario.task.supports
    paths = np.full((n_supports, len(work)), -1, dtype=int)
    for _ in range(scenario.planner.rounds):
        for n in range(n_supports):
            others = [paths[m] for m in range(n_supports) if m != n and paths[m][0] >= 0]
            paths[n] = _plan_one(world, work, candidates, reach, legs_clear, others, n)
    supports = np.array(
        [[candidates[i].points[paths[n][i]] for i in range(len(work))] for n in range(n_supports)]
    )
    return Plan(work=work, supports=supports)


def _check_work_waypoints(world: KnownWorld, work: np.ndarray) -> None:
    inside = world.structure.contains(work)
    for i in np.flatnonzero(inside):
        raise PlanningError(
            world.scenario.source,
            f"task.work_waypoints_m[{i}]",
            f"work waypoint {i + 1} {work[i].tolist()} lies inside the structure",
        )
    for i, point in enumerate(work):
        problem = world.clearance_problem(point)
        if problem is not None:
            raise PlanningError(
                world.scenario.source,
                f"task.work_waypoints_m[{i}]",
                f"work waypoint {i + 1} {point.tolist()} lies {problem}",
            )


def _admissible_points(world: KnownWorld) -> tuple[np.ndarray, np.ndarray]:
    """Lattice points clear of structure and ground, with a fix; and their sigma_0^2."""
    settings = world.scenario.planner
    lattice = VoxelGrid.over(world.workspace, settings.lattice_m).centers().reshape(-1, 3)
    keep = lattice[:, 2] >= settings.min_altitude_m
    keep &= ~world.structure.contains(lattice)
    lattice = lattice[keep]
    if settings.clearance_m > 0:
        import trimesh  # only planning needs it; the run's processes import this module

        _, distance, _ = trimesh.proximity.closest_point(world.structure.mesh, lattice)
        lattice = lattice[distance >= settings.clearance_m]
    sigma0 = world.gnss.sigma0(lattice)
    fixed = np.isfinite(sigma0)
    return lattice[fixed], sigma0[fixed] ** 2


def _candidates_for(
    world: KnownWorld, admissible: tuple[np.ndarray, np.ndarray], waypoint: np.ndarray, index: int
) -> _Candidates:
    points, sigma0_sq = admissible
    settings = world.scenario.planner
    max_range = settings.max_range_fraction * world.scenario.camera.range_m
    distance = np.linalg.norm(points - waypoint, axis=1)
    # no closer to the work UAV than the run's separation margin (where there is one)
    closest = world.scenario.control.min_separation_m
    near = np.flatnonzero((distance <= max_range) & (distance > 0) & (distance >= closest))
    visible = near[~world.structure.segments_blocked(points[near], waypoint[None])]
    if len(visible) == 0:
        raise PlanningError(
            world.scenario.source,
            f"task.work_waypoints_m[{index}]",
            f"no support can see work waypoint {index + 1} {waypoint.tolist()} from any "
            "admissible point (clear of the structure, with a fix, within camera range)",
        )
    relative = np.trace(world.camera.covariance(waypoint - points[visible]), axis1=1, axis2=2)
    cost = settings.w_gnss_per_m2 * sigma0_sq[visible] + settings.w_relative_per_m2 * relative
    cost = _settled(cost)
    best = np.argsort(cost, kind="stable")[:CANDIDATES_PER_INDEX]
    return _Candidates(points[visible][best], cost[best])


def _plan_one(
    world: KnownWorld,
    work: np.ndarray,
    candidates: list[_Candidates],
    reach: np.ndarray,
    legs_clear: list[np.ndarray],
    others: list[np.ndarray],
    support: int,
) -> np.ndarray:
    """Dynamic programming over the waypoint index for one support, the others fixed."""
    settings = world.scenario.planner
    total = _stage_cost(settings, work[0], candidates[0], candidates, others, 0)
    back: list[np.ndarray] = []
    for i in range(1, len(work)):
        previous, current = candidates[i - 1].points, candidates[i].points
        step = np.linalg.norm(current[:, None, :] - previous[None, :, :], axis=2)
        transition = total[None, :] + settings.w_move_per_m * step
        transition[step > reach[i - 1]] = np.inf
        transition[~legs_clear[i - 1]] = np.inf
        choice = np.argmin(_settled(transition), axis=1)
        total = transition[np.arange(len(current)), choice] + _stage_cost(
            settings, work[i], candidates[i], candidates, others, i
        )
        back.append(choice)
        if not np.any(np.isfinite(total)):
            raise PlanningError(
                world.scenario.source,
                f"task.work_waypoints_m[{i}]",
                f"support {support + 1} cannot reach an admissible point for work waypoint "
                f"{i + 1} in time (or keep its separation)",
            )
    path = np.empty(len(work), dtype=int)
    path[-1] = int(np.argmin(_settled(total)))
    for i in range(len(work) - 1, 0, -1):
        path[i - 1] = back[i - 1][path[i]]
    return path


def _settled(cost: np.ndarray) -> np.ndarray:
    """Costs rounded to COST_DECIMALS: candidates a lattice's symmetry makes equal stay
    equal whatever the last bits of numpy's kernels (AVX2 or SSE), and the first index wins."""
    return np.round(cost, COST_DECIMALS)


def _legs_clear(world: KnownWorld, previous: np.ndarray, current: np.ndarray) -> np.ndarray:
    """(K_i, K_{i-1}) True where flying straight between the two points misses the structure."""
    starts = np.broadcast_to(previous[None, :, :], (len(current), len(previous), 3)).reshape(-1, 3)
    ends = np.broadcast_to(current[:, None, :], (len(current), len(previous), 3)).reshape(-1, 3)
    blocked = world.structure.segments_blocked(starts, ends)
    return ~blocked.reshape(len(current), len(previous))


def _stage_cost(
    settings,
    waypoint: np.ndarray,
    stage: _Candidates,
    candidates: list[_Candidates],
    others: list[np.ndarray],
    index: int,
) -> np.ndarray:
    cost = stage.base_cost.copy()
    if not others:
        return cost
    mine = stage.points - waypoint
    mine_unit = mine / np.linalg.norm(mine, axis=1, keepdims=True)
    for path in others:
        other = candidates[index].points[path[index]]
        separation = np.linalg.norm(stage.points - other, axis=1)
        cost[separation < settings.min_separation_m] = np.inf
        direction = (other - waypoint) / np.linalg.norm(other - waypoint)
        cost += settings.w_spread * (mine_unit @ direction) ** 2
    return cost
