"""The rows of the ground station's control cycles (``records.jsonl``): the estimates, which
supports were fused (S), each support's role, beta_n, each MPC's solve time and predicted
path, the current waypoint, the integrity monitor's exclusions and protection radii; and,
once the truth has reached a cycle's time, the work UAV's error and the steps each support
has spent in a zone (counted as the metrics count them)."""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np

from mission.viewer import frame as f
from mission.viewer.safety_rows import SafetyRows
from mission.world.model import World


class TruthSource(Protocol):
    """What the cycles need of the truth read so far (:class:`~.assemble.RunAssembler`)."""

    names: dict[int, str]
    tracks: dict[str, Any]
    world: World

    def ready(self, names: list[str], t: float, final: bool) -> bool: ...

    def truth_at(self, name: str, times: list[float]) -> tuple[np.ndarray, np.ndarray]: ...


class CycleRows:
    """Per-cycle rows, from records fed in order."""

    def __init__(self, run: TruthSource, waypoints: dict[str, np.ndarray]) -> None:
        self.run = run
        self.waypoints = waypoints
        self.times: list[float] = []  # every cycle's time so far
        self.zone_steps = {n: 0 for n in run.names.values() if n != "work"}
        self._waypoint: int | None = None
        self._pending: list[tuple[float, np.ndarray | None]] = []  # (t, xhat) awaiting truth
        self.safety = SafetyRows(run.world, list(run.names.values()))

    def add(self, records: list[dict[str, Any]], out: f.Frame) -> None:
        for record in records:
            t = float(record["t"])
            self.times.append(t)
            xhat = np.array(record["xhat"], dtype=float)
            out.points[f.estimate_path("work")].add(t, xhat, f.ESTIMATE_COLOUR)
            fused = set(record.get("consistent", []))
            for name, yhat in record.get("yhat", {}).items():
                colour = f.colour_of(name) if name in fused else f.EXCLUDED_COLOUR
                out.points[f.estimate_path(name)].add(t, np.array(yhat, dtype=float), colour)
                out.scalars[f.scalar_path("fused", name)].add(t, float(name in fused))
            for name, role in record.get("roles", {}).get("roles", {}).items():
                badge = np.array(record["yhat"][name], dtype=float) + f.ROLE_BADGE_M
                out.points[f.role_path(name)].add(t, badge, f.role_colour(name, role))
                out.scalars[f.scalar_path("role", name)].add(t, f.ROLE_LEVELS[role])
            for name, beta in record.get("beta", {}).items():
                if beta is not None:  # None: the support gave no measurement this cycle
                    out.scalars[f.scalar_path("beta", name)].add(t, float(beta))
            for name, solve in record.get("mpc", {}).items():
                out.scalars[f.scalar_path("solve_ms", name)].add(t, float(solve["ms"]))
                if solve.get("path"):
                    path = np.array(solve["path"], dtype=float).reshape(-1, 3)
                    out.strips[f.mpc_path(name)].add(t, path, f.colour_of(name))
            if "integrity" in record:
                _integrity_rows(record, t, out)
            self._current_waypoint(int(record["k"]), t, out)
            self._pending.append((t, None if record.get("blind") else xhat))

    def _current_waypoint(self, k: int, t: float, out: f.Frame) -> None:
        """Each vehicle's current waypoint w_{n,k}, logged when k changes."""
        if k == self._waypoint:
            return
        self._waypoint = k
        for name, points in self.waypoints.items():
            if len(points):
                point = points[min(max(k, 0), len(points) - 1)]
                out.points[f.current_waypoint_path(name)].add(t, point, f.colour_of(name))

    def resolve(self, out: f.Frame, final: bool) -> None:
        """The error, the steps in a zone and the margins of the cycles whose truth has come."""
        names = list(self.run.tracks)
        ready = [(t, x) for t, x in self._pending if self.run.ready(names, t, final)]
        self._pending = self._pending[len(ready) :]
        if not ready:
            return
        times = [t for t, _ in ready]
        truth, known = self.run.truth_at("work", times)
        for (t, xhat), position, ok in zip(ready, truth, known):
            if ok and xhat is not None:  # a blind cycle has no estimate to be wrong
                error = float(np.linalg.norm(xhat - position))
                out.scalars[f.scalar_path("work_error")].add(t, error)
        at = {name: self.run.truth_at(name, times) for name in names}
        for i, t in enumerate(times):
            known = {name: p[i] for name, (p, k) in at.items() if k[i]}
            self.safety.add(t, known, out)
        for name in self.zone_steps:
            positions, known = self.run.truth_at(name, times)
            inside = np.zeros(len(times), dtype=bool)
            if known.any():
                inside[known] = self.run.world.in_zone(positions[known])
            for t, hit in zip(times, inside):
                self.zone_steps[name] += int(hit)
                out.scalars[f.scalar_path("zone_steps", name)].add(t, self.zone_steps[name])


def _integrity_rows(record: dict[str, Any], t: float, out: f.Frame) -> None:
    """An excluded support's badge (a zero-sized one otherwise), and each estimate's
    protection radius as a sphere around it."""
    integrity = record["integrity"]
    excluded = set(integrity.get("excluded", []))
    positions = {"work": record["xhat"], **record.get("yhat", {})}
    for name, yhat in record.get("yhat", {}).items():
        badge = np.array(yhat, dtype=float) + f.EXCLUSION_BADGE_M
        radius = f.EXCLUSION_RADIUS_M if name in excluded else 0.0
        out.points[f.exclusion_path(name)].add(t, badge, f.EXCLUSION_COLOUR, radius)
    for name, radius in integrity.get("protection_m", {}).items():
        if radius is not None and name in positions:
            centre = np.array(positions[name], dtype=float)
            out.spheres[f.protection_path(name)].add(t, centre, f.colour_of(name), radius)
