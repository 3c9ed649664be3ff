"""From a run's messages and records to the view's rows (:class:`~mission.viewer.frame.Frame`).

Times are the ground station's simulated seconds, as in the metrics: a vehicle's stamp (SIM_STATE's
step, a GNSS fix's or a camera sighting's ``time_usec``) is mapped onto the station's clock the
way :mod:`mission.analysis.truth` does (in lockstep all clocks are the station's; in real time
by the TIMESYNC offset with the shortest round trip seen so far). What needs the truth at a
time (a fix's zone, a sight line's ends, the work UAV's error, the steps in a zone) waits until
the truth has reached that time, or the run is over.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from mission.analysis.metrics import GCS_SYSTEM_ID
from mission.analysis.truth import interpolate, truth_time
from mission.config.settings import Scenario
from mission.link.plan_files import vehicle_names
from mission.link.timesync import exchange_offset
from mission.viewer import frame as f
from mission.viewer.cycles import CycleRows
from mission.world.frames import GeodeticFrame, quaternion_matrix, swap_attitude_frames
from mission.world.model import World


@dataclass
class Track:
    """A vehicle's truth so far."""

    times: list[float]
    positions: list[np.ndarray]

    def at(self, times: list[float], max_gap_s: float) -> tuple[np.ndarray, np.ndarray]:
        return interpolate(
            np.array(self.times), np.array(self.positions).reshape(-1, 3), times, max_gap_s
        )

    @property
    def last(self) -> float:
        return self.times[-1] if self.times else float("-inf")


@dataclass(frozen=True)
class Stamped:
    """Something a vehicle stamped with its own clock: a truth sample, a fix or a sighting."""

    kind: str  # "truth", "fix", "sight"
    system: int
    stamp_usec: int
    value: Any  # a position (truth, fix) or whether the camera saw the work UAV (sight)


class RunAssembler:
    """Turns messages and records, fed as they come, into frames of rows."""

    def __init__(self, scenario: Scenario, world: World, waypoints: dict[str, np.ndarray]) -> None:
        self.world = world
        self.frame_of = GeodeticFrame(scenario.world.anchor)
        self.epoch_s = scenario.run.epoch_unix_s
        self.epoch_usec = round(self.epoch_s * 1e6)
        sample_s = max(scenario.control.t_cont_s, 1.0 / scenario.vehicle.sensor_hz)
        self.max_gap_s = 2 * sample_s
        self.names = {i + 1: n for i, n in enumerate(vehicle_names(scenario.task.supports))}
        self.tracks = {n: Track([], []) for n in self.names.values()}
        self.lockstep = False
        self.offsets: dict[int, tuple[int, float]] = {}  # system: (round trip ns, offset s)
        self.flying = scenario.vehicle.dynamics == "multicopter"  # SIM_STATE has an attitude
        self._unstamped: dict[int, tuple] = {}  # SIM_STATE awaiting its SYSTEM_TIME
        self._stamped: list[Stamped] = []  # awaiting the clock offset of their vehicle
        self._fixes: list[tuple[str, float, np.ndarray]] = []  # awaiting the truth
        self._sights: list[tuple[str, float, bool]] = []
        self.cycles = CycleRows(self, waypoints)

    def feed(self, messages: list[Any], records: list[dict[str, Any]], final: bool) -> f.Frame:
        """The rows that the new messages and records complete (``final``: the run is over,
        so nothing more will come)."""
        out = f.Frame()
        for message in messages:
            self._take(message)
        self._convert(out)
        self.cycles.add(records, out)
        self._resolve_fixes(out, final)
        self._resolve_sights(out, final)
        self.cycles.resolve(out, final)
        return out

    def _take(self, message: Any) -> None:
        kind, source = message.get_type(), message.get_srcSystem()
        if source == GCS_SYSTEM_ID:
            if kind == "SYSTEM_TIME" and message.time_boot_ms > 0:
                self.lockstep = True  # only a lockstep station sends clock ticks
            return
        if source not in self.names:
            return
        if kind == "SIM_STATE":
            point = self.frame_of.from_degE7(message.lat_int, message.lon_int, message.alt)
            attitude = (message.q1, message.q2, message.q3, message.q4) if self.flying else None
            self._unstamped[source] = (point, attitude)
        elif kind == "SYSTEM_TIME" and source in self._unstamped:
            truth = self._unstamped.pop(source)
            self._stamped.append(Stamped("truth", source, int(message.time_unix_usec), truth))
        elif kind == "GPS_RAW_INT" and message.fix_type >= 3:
            point = self.frame_of.from_degE7(message.lat, message.lon, message.alt / 1000.0)
            self._stamped.append(Stamped("fix", source, int(message.time_usec), point))
        elif kind == "LANDING_TARGET":
            seen = bool(message.position_valid)
            self._stamped.append(Stamped("sight", source, int(message.time_usec), seen))
        elif kind == "TIMESYNC":
            received_ns = round(message._timestamp * 1e9 - self.epoch_s * 1e9)
            exchange = exchange_offset(message.tc1, message.ts1, received_ns)
            if exchange is not None and exchange[0] < self.offsets.get(source, (np.inf,))[0]:
                self.offsets[source] = (exchange[0], exchange[1] / 1e9)

    def _convert(self, out: f.Frame) -> None:
        """Stamps of vehicles whose clock is known, onto the station's clock."""
        waiting = []
        for item in self._stamped:
            if not self.lockstep and item.system not in self.offsets:
                waiting.append(item)
                continue
            offset = 0.0 if self.lockstep else self.offsets[item.system][1]
            t = truth_time(item.stamp_usec, self.epoch_usec, offset)
            name = self.names[item.system]
            if item.kind == "truth":
                if t <= self.tracks[name].last:  # a step's telemetry sent again (lockstep)
                    continue
                position, attitude = item.value
                self.tracks[name].times.append(t)
                self.tracks[name].positions.append(position)
                out.points[f.uav_path(name)].add(t, position, f.colour_of(name))
                if attitude is not None:
                    out.strips[f.axes_path(name)].add(
                        t, body_axes(position, attitude), f.colour_of(name)
                    )
            elif item.kind == "fix":
                self._fixes.append((name, t, item.value))
            else:
                self._sights.append((name, t, item.value))
        self._stamped = waiting

    def truth_at(self, name: str, times: list[float]) -> tuple[np.ndarray, np.ndarray]:
        """A vehicle's truth at these times, and which are known."""
        return self.tracks[name].at(times, self.max_gap_s)

    def ready(self, names: list[str], t: float, final: bool) -> bool:
        """Whether the truth of these vehicles has reached time ``t`` (or will not come)."""
        return final or all(self.tracks[n].last >= t for n in names)

    def _resolve_fixes(self, out: f.Frame, final: bool) -> None:
        """Each fix, coloured by whether its support was in a zone (truth at the fix's time)."""
        ready, self._fixes = self._split(self._fixes, lambda item: [item[0]], final)
        for name, items in _by_name(ready).items():
            truth, known = self.truth_at(name, [t for _, t, _ in items])
            inside = np.zeros(len(items), dtype=bool)
            if known.any():
                inside[known] = self.world.in_zone(truth[known])
            for (_, t, position), ok, hit in zip(items, known, inside):
                colour = f.colour_of(name) if ok else f.UNKNOWN_COLOUR
                out.points[f.fix_path(name)].add(
                    t, position, f.IN_ZONE_FIX_COLOUR if hit else colour
                )

    def _resolve_sights(self, out: f.Frame, final: bool) -> None:
        """Each sighting, as the line between the true support and the true work UAV."""
        ready, self._sights = self._split(self._sights, lambda item: [item[0], "work"], final)
        for name, items in _by_name(ready).items():
            times = [t for _, t, _ in items]
            starts, known_starts = self.truth_at(name, times)
            ends, known_ends = self.truth_at("work", times)
            for index, (_, t, seen) in enumerate(items):
                if known_starts[index] and known_ends[index]:
                    colour = f.VISIBLE_COLOUR if seen else f.BLOCKED_COLOUR
                    line = np.vstack([starts[index], ends[index]])
                    out.strips[f.sight_path(name)].add(t, line, colour)

    def _split(self, items: list, needs, final: bool) -> tuple[list, list]:
        """(ready, still waiting) of items (name, time, value) whose truth has come."""
        ready, waiting = [], []
        for item in items:
            (ready if self.ready(needs(item), item[1], final) else waiting).append(item)
        return ready, waiting


def _by_name(items: list[tuple]) -> dict[str, list[tuple]]:
    grouped: dict[str, list[tuple]] = {}
    for item in items:
        grouped.setdefault(item[0], []).append(item)
    return grouped


NOSE_M, UP_M = 0.5, 0.8  # the drawn body axes' lengths


def body_axes(position: np.ndarray, quaternion_ned_frd: tuple[float, ...]) -> np.ndarray:
    """(3, 3): the nose's tip, the centre and the thrust axis' tip (ENU), from SIM_STATE's
    attitude (body FRD to world NED)."""
    enu = swap_attitude_frames(quaternion_matrix(quaternion_ned_frd))  # body FLU to world ENU
    return np.vstack([position + NOSE_M * enu[:, 0], position, position + UP_M * enu[:, 2]])
