"""Task allocation: which supports the formation needs now, and where the others fly.

Each support is in one of three roles:

- ``formation``: planned by its MPC around the work UAV (the paper's role);
- ``inspecting``: flying a route (:mod:`mission.world.routes`) to its next inspection
  waypoint (``task.inspections``), then the next, until it has reached them all;
- ``returning``: flying a route back to its formation waypoint; within ``TRANSIT_M`` of it
  with no structure in the straight way (or at the route's end) its MPC takes it again. A
  formation support whose waypoint lies behind the structure (the straight way to it comes
  within the clearance margin of it, and it is more than ``TRANSIT_M`` away) is sent the
  same way: the MPC plans locally, and a pier or the deck between it and its waypoint can
  hold it (in the piers scenario one such support, GNSS-denied under the deck, drifted into
  the east pier).

With ``roles.policy: dynamic``, each cycle the work UAV's path ahead is looked at
(:mod:`ground_station.roles.lookahead`): where its own fix is expected trustworthy for
``release_clear_s`` or more (or to the end of its task), supports with inspections left are
released, all but ``keep_in_formation`` (the farthest from the work UAV first), each only if
it can reach its next inspection waypoint before it would be recalled (the straight way at
its speed within the look-ahead less ``recall_clear_s``); where it is
expected for less than ``recall_clear_s``, every inspecting support is recalled. Between the
two nothing changes: a path along a shadow's edge recalls once and releases again only with
``release_clear_s`` of open sky ahead (the hysteresis). With ``fixed`` (the paper), supports
go inspecting only once the work UAV's task is complete. A support that has reached all its
inspection waypoints returns to the formation (or, the task complete, holds there).

A route keeps off the other UAVs' estimates by the separation widened by two estimates'
allowance. A routed support steps along it by at most its reach; where that step would bring
it that close to another UAV's estimate, and closer, it steps away from that UAV instead
(straight away, or up, down or sideways where straight away closes on the structure; it
holds only where every way does: it gives way: the work UAV and the
formation's MPCs plan around it from its estimate and its predicted route); after
``REROUTE_AFTER`` such cycles since its route was planned it is routed afresh round the
others where they are then, and so it is where a step aside left it off its route with the
straight way back cutting the margin.
"""

from __future__ import annotations

import math
from typing import Protocol

import numpy as np

from ground_station.estimation.gnss_map import LocalizabilityMap
from ground_station.roles.lookahead import clear_ahead_s, points_along
from ground_station.state.assignment import (
    FORMATION,
    INSPECTING,
    RETURNING,
    Allocation,
    SupportRole,
)
from ground_station.state.station_state import StationState
from ground_station.support_mpc.mpc import SupportPlan
from mission.config.settings import Scenario
from mission.world.routes import RouteMap

CORNER_TOL_M = 0.3  # a route's corner (not an inspection waypoint) is passed this close
REROUTE_AFTER = 10  # cycles held giving way before a route round the others is sought
LOOK_AHEAD_FACTOR = 2.0  # the path is looked at this many release_clear_s ahead
TRANSIT_M = 4.0  # a formation support farther from its waypoint, behind the structure, is routed


class RoleContext(Protocol):
    """What the task allocation reads of the run: the scenario, the planned waypoints, the map
    G, the supports' inspections and the routes to fly them (None without inspections). The
    control cycle's context has them all."""

    scenario: Scenario
    work_waypoints: np.ndarray
    support_waypoints: dict[str, np.ndarray]
    g: LocalizabilityMap
    inspections: dict[str, np.ndarray]
    routes: RouteMap | None


def inspections_left(allocation: Allocation, context: RoleContext) -> bool:
    """Whether a support has inspection waypoints it has not reached."""
    return any(
        allocation.supports.get(n, SupportRole()).next_inspection < len(points)
        for n, points in context.inspections.items()
    )


def allocate(state: StationState, context: RoleContext, allocation: Allocation) -> None:
    """This cycle's roles (``allocation`` updated in place): progress along the routes, then
    release and recall. Without inspections in the scenario nothing happens."""
    if not context.inspections:
        return
    for name in context.inspections:
        allocation.supports.setdefault(name, SupportRole())
    _progress(state, context, allocation)
    _send_round_the_structure(state, context, allocation)
    roles = context.scenario.roles
    if roles.policy == "dynamic" and not state.completed:
        allocation.clear_s = clear_ahead_s(
            state.xhat,
            state.k,
            context.work_waypoints,
            context.g,
            roles.own_fix_max_sigma_m,
            context.scenario.control.s_max_work_m_s,
            LOOK_AHEAD_FACTOR * roles.release_clear_s,
        )
    else:
        allocation.clear_s = math.inf if state.completed else 0.0
    if allocation.clear_s < roles.recall_clear_s:
        for name, support in allocation.supports.items():
            if support.role == INSPECTING:
                _set(allocation, name, RETURNING, _route_home(state, context, name))
    elif allocation.clear_s >= roles.release_clear_s:
        _release(state, context, allocation)


def _send_round_the_structure(
    state: StationState, context: RoleContext, allocation: Allocation
) -> None:
    """A formation support more than ``TRANSIT_M`` from its formation waypoint with the
    structure in the straight way (within the clearance margin of it) is routed there
    (``returning``): its MPC plans locally and can be held behind a pier or the deck."""
    assert context.routes is not None
    margin = _transit_margin(context)
    for name, support in allocation.supports.items():
        if support.role != FORMATION:
            continue
        home = _formation_waypoint(state, context, name)
        yhat = state.yhat[name]
        if np.linalg.norm(home - yhat) <= TRANSIT_M:
            continue
        if context.routes.structure_between(yhat, home, margin):
            _set(allocation, name, RETURNING, _routed(state, context, name, home))


def _release(state: StationState, context: RoleContext, allocation: Allocation) -> None:
    keep = 0 if state.completed else context.scenario.roles.keep_in_formation
    limit = len(state.yhat) - keep
    out = sum(1 for s in allocation.supports.values() if s.role == INSPECTING)
    # only a support that can reach its next inspection waypoint before it would be recalled
    # (by the straight way at its speed: no route can be shorter)
    available_s = allocation.clear_s - context.scenario.roles.recall_clear_s
    speed = context.scenario.control.s_max_support_m_s
    candidates = [
        n
        for n, s in allocation.supports.items()
        if s.role != INSPECTING
        and s.next_inspection < len(context.inspections[n])
        and np.linalg.norm(context.inspections[n][s.next_inspection] - state.yhat[n]) / speed
        <= available_s
    ]
    candidates.sort(key=lambda n: (-float(np.linalg.norm(state.yhat[n] - state.xhat)), n))
    for name in candidates[: max(0, limit - out)]:
        _set(allocation, name, INSPECTING, _route_to_inspection(state, context, allocation, name))


def _progress(state: StationState, context: RoleContext, allocation: Allocation) -> None:
    """Corners passed, inspection waypoints reached, returns completed."""
    tol = context.scenario.roles.inspection_tol_m
    for name, support in allocation.supports.items():
        if support.role == FORMATION:
            continue
        yhat = state.yhat[name]
        if support.held >= REROUTE_AFTER and support.route is not None:  # a way round them
            support.route, support.held = _routed(state, context, name, support.route[-1]), 0
        elif support.route is not None and not context.routes.leads_on(yhat, support.route[0]):
            # off its route (it gave way): the straight way back to it would cut the margin
            support.route, support.held = _routed(state, context, name, support.route[-1]), 0
        while support.route is not None and len(support.route) > 1:
            if np.linalg.norm(support.route[0] - yhat) >= CORNER_TOL_M:
                break
            support.route = support.route[1:]
        waypoints = context.inspections[name]
        if support.role == INSPECTING and support.next_inspection < len(waypoints):
            if np.linalg.norm(waypoints[support.next_inspection] - yhat) < tol:
                support.next_inspection += 1
                if support.next_inspection < len(waypoints):
                    support.route = _route_to_inspection(state, context, allocation, name)
                elif state.completed:  # all done, the task too: it holds where it is
                    support.route = np.array([yhat])
                else:
                    _set(allocation, name, RETURNING, _route_home(state, context, name))
        elif support.role == RETURNING:
            home = _formation_waypoint(state, context, name)
            at_end = np.linalg.norm(support.route[-1] - yhat) < CORNER_TOL_M
            if _mpc_can_take(context, yhat, home) or at_end:
                _set(allocation, name, FORMATION, None)
                state.warm.pop(name, None)  # its MPC starts afresh from where it is


def _mpc_can_take(context: RoleContext, yhat: np.ndarray, home: np.ndarray) -> bool:
    """Within ``TRANSIT_M`` of its formation waypoint with no structure in the straight way
    (the formation's other supports, which a routed support gives way to, can keep it
    metres from its waypoint)."""
    assert context.routes is not None
    if np.linalg.norm(home - yhat) >= TRANSIT_M:
        return False
    return not context.routes.structure_between(yhat, home, _transit_margin(context))


def _transit_margin(context: RoleContext) -> float:
    control, vehicle = context.scenario.control, context.scenario.vehicle
    return max(control.clearance_m, vehicle.radius_m)


def _set(allocation: Allocation, name: str, role: str, route: np.ndarray | None) -> None:
    support = allocation.supports[name]
    if support.role != role:
        allocation.switches += 1
    support.role, support.route, support.held = role, route, 0


def _formation_waypoint(state: StationState, context: RoleContext, name: str) -> np.ndarray:
    waypoints = context.support_waypoints[name]
    return waypoints[min(state.k, len(waypoints) - 1)]


def _route_to_inspection(state, context, allocation, name) -> np.ndarray:
    goal = context.inspections[name][allocation.supports[name].next_inspection]
    return _routed(state, context, name, goal)


def _route_home(state: StationState, context: RoleContext, name: str) -> np.ndarray:
    return _routed(state, context, name, _formation_waypoint(state, context, name))


def _routed(state: StationState, context: RoleContext, name: str, goal: np.ndarray) -> np.ndarray:
    """The corners after the support's estimate of a route to ``goal`` that keeps off the
    other UAVs' estimates by the separation; where they close every way, one that does not
    (it gives way as it goes); where the structure does, none: it holds."""
    assert context.routes is not None
    start = state.yhat[name]
    others = np.array([state.xhat, *(p for n, p in state.yhat.items() if n != name)])
    route = context.routes.route(start, goal, others, _crowding_m(context))
    if route is None:
        route = context.routes.route(start, goal)
    return np.array([start]) if route is None else route[1:]


def _crowding_m(context: RoleContext) -> float:
    """How close to another UAV's estimate a routed support does not go: the separation
    widened by two vehicles' allowance (0: no separation margin)."""
    control = context.scenario.control
    if control.min_separation_m <= 0:
        return 0.0
    return control.min_separation_m + 2 * control.allowance_m


def routed_plans(state: StationState, context: RoleContext, allocation: Allocation):
    """{name: plan} of every support off the formation: its route's next steps (the first is
    its command), or, where that step would crowd another UAV, a step away from it."""
    control = context.scenario.control
    reach = control.s_max_support_m_s * control.t_cont_s
    horizon = control.horizon_steps
    plans = {}
    for name, support in allocation.supports.items():
        if support.role == FORMATION:
            continue
        yhat = state.yhat[name]
        path = _along(yhat, support.route, reach, horizon)
        away = _give_way(state, context, name, path[0])
        support.held += away is not None  # since its route was planned
        if away is not None:
            path = np.repeat(away[None], horizon, axis=0)
        blocked = np.zeros(horizon, dtype=bool)
        plans[name] = SupportPlan(path, support.role.upper(), 0.0, blocked, False, np.zeros(0))
    return plans


def _along(start: np.ndarray, route: np.ndarray | None, reach: float, steps: int) -> np.ndarray:
    """``steps`` positions a reach apart along the route's corners from ``start``."""
    corners = np.vstack([start[None], route]) if route is not None else start[None]
    return points_along(corners, reach * np.arange(1, steps + 1))


def _give_way(state, context, name, command) -> np.ndarray | None:
    """A step away from the nearest UAV whose separation ``command`` would break (and come
    closer), or None: straight away, else the first of away-and-up, away-and-down, sideways
    and straight up or down that moves away from it without closing on the structure inside
    the route margin; where none does, it holds."""
    control = context.scenario.control
    needed = _crowding_m(context)
    if needed <= 0:
        return None
    yhat = state.yhat[name]
    others = [state.xhat, *(p for n, p in state.yhat.items() if n != name)]
    crowded = [
        o
        for o in others
        if np.linalg.norm(command - o) < needed
        and np.linalg.norm(command - o) < np.linalg.norm(yhat - o)
    ]
    if not crowded:
        return None
    nearest = min(crowded, key=lambda o: float(np.linalg.norm(yhat - o)))
    away = _unit(yhat - nearest)
    side = _unit(np.cross(away, UP)) if abs(away[2]) < 0.99 else np.array([1.0, 0.0, 0.0])
    reach = control.s_max_support_m_s * control.t_cont_s
    assert context.routes is not None
    now = float(context.routes.proximity.clearance(yhat[None])[0])
    for direction in (away, away + UP, away - UP, side, -side, UP, -UP):
        step = yhat + _unit(direction) * reach
        if np.linalg.norm(step - nearest) <= np.linalg.norm(yhat - nearest):
            continue
        after = float(context.routes.proximity.clearance(step[None])[0])
        if after >= context.routes.margin_m or after > now:  # never closer inside the margin
            return step
    return yhat.copy()


UP = np.array([0.0, 0.0, 1.0])


def _unit(vector: np.ndarray) -> np.ndarray:
    return vector / max(float(np.linalg.norm(vector)), 1e-9)
