"""Metrics of a run from its tlog alone (plus the scenario's zones), as the paper's Table 3 counts.

- truth: SIM_STATE of each vehicle at its own time stamp, on the ground station's clock
  (:mod:`mission.analysis.truth`), interpolated between samples where needed;
- the control cycles: one SET_POSITION_TARGET_LOCAL_NED to the work UAV each, at its time;
- the work UAV's estimate: the VISION_POSITION_ESTIMATE the ground station sent it before a
  cycle's setpoint (the setpoint names the vehicle); a blind cycle sends none;
- the mode: lockstep where the ground station sent clock ticks (SYSTEM_TIME), else real time;
- completion: the ground station's "Mission complete" STATUSTEXT.

The same holds in both modes: in lockstep every truth sample falls on a cycle's time.
"""

from __future__ import annotations

import os
import re
from collections import defaultdict
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

os.environ.setdefault("MAVLINK20", "1")
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.analysis.gnss_errors import gnss_error_metrics
from mission.analysis.safety import safety_metrics
from mission.analysis.spread import spread
from mission.analysis.trace import RunTrace
from mission.analysis.tracking import tracking_metrics
from mission.analysis.truth import TimesyncReply, clock_offsets, truth_time
from mission.config.errors import InputError
from mission.config.settings import Scenario
from mission.link.fast_decode import FastDecoder
from mission.link.statustext import StatusChunks
from mission.link.vehicle_events import parse_event
from mission.link.vehicle_identity import VehicleIdentity
from mission.world.frames import (
    GeodeticFrame,
    ned_to_enu,
    quaternion_matrix,
    swap_attitude_frames,
)
from mission.world.model import World

GCS_SYSTEM_ID = 255
MIN_3D_FIX = 3
_LINK_EVENT = re.compile(r"^support-\d+ (lost|back)")
_CONTACT = re.compile(r"^(Crash|Contact): (\S+) t=(-?[\d.]+) at (-?[\d.]+),(-?[\d.]+),(-?[\d.]+)")
_WANTED_IDS = frozenset(
    {
        mavlink2.MAVLINK_MSG_ID_SIM_STATE,
        mavlink2.MAVLINK_MSG_ID_LOCAL_POSITION_NED,
        mavlink2.MAVLINK_MSG_ID_GPS_RAW_INT,
        mavlink2.MAVLINK_MSG_ID_VISION_POSITION_ESTIMATE,
        mavlink2.MAVLINK_MSG_ID_SET_POSITION_TARGET_LOCAL_NED,
        mavlink2.MAVLINK_MSG_ID_SYSTEM_TIME,
        mavlink2.MAVLINK_MSG_ID_STATUSTEXT,
        mavlink2.MAVLINK_MSG_ID_TIMESYNC,
    }
)

VELOCITY_IGNORED = 0b0000_0000_0011_1000  # SET_POSITION_TARGET's velocity bits, all set


def read_tlog(tlog: Path, scenario: Scenario) -> RunTrace:
    """Truth (SIM_STATE), the work UAV's estimates, clock ticks and completion from a tlog."""
    return trace_of_messages(_tlog_messages(tlog), scenario)


def pymavlink_messages(tlog: Path) -> Iterator[Any]:
    """Every message of a tlog through pymavlink's tolerant reader (every message decoded;
    slower than the fast path, which falls back to it for a file it cannot index)."""
    from pymavlink import mavutil  # 0.1 s to import (every dialect); the fast path needs none

    try:
        log = mavutil.mavlink_connection(str(tlog), dialect="ardupilotmega", robust_parsing=True)
        while (message := log.recv_match()) is not None:
            yield message
    except (AttributeError, TypeError, ValueError, IndexError, KeyError) as error:
        # pymavlink's reader itself failed on the bytes (not one of ours): a damaged file
        raise InputError(
            str(tlog), "", f"is damaged: pymavlink cannot read it ({type(error).__name__})"
        ) from None


def trace_of_messages(messages: Iterable[Any], scenario: Scenario) -> RunTrace:
    """What :func:`read_tlog` makes of a tlog, from its messages however they were decoded
    (pymavlink's own reader gives the same)."""
    frame = GeodeticFrame(scenario.world.anchor)
    epoch = scenario.run.epoch_unix_s
    sample_s = max(scenario.control.t_cont_s, 1.0 / scenario.vehicle.sensor_hz)
    trace = RunTrace(max_gap_s=2 * sample_s)
    pending_estimate: tuple[float, np.ndarray] | None = None
    samples = _StepSamples()
    replies: list[TimesyncReply] = []
    chunks = StatusChunks()  # the ground station's long STATUSTEXTs
    vehicle_texts = _VehicleTexts()
    for message in messages:
        kind = message.get_type()
        t = round(message._timestamp - epoch, 3)
        source = message.get_srcSystem()
        if kind == "SIM_STATE" and source != GCS_SYSTEM_ID:
            truth = frame.from_degE7(message.lat_int, message.lon_int, message.alt)
            samples.pending[TRUTH][source] = truth
            attitude = (message.q1, message.q2, message.q3, message.q4)
            samples.pending[ATTITUDE][source] = swap_attitude_frames(quaternion_matrix(attitude))
        elif kind == "GPS_RAW_INT" and source != GCS_SYSTEM_ID:
            if message.fix_type >= MIN_3D_FIX:
                fix = frame.from_degE7(message.lat, message.lon, message.alt / 1000.0)
                samples.pending[FIX][source] = fix
        elif kind == "LOCAL_POSITION_NED" and source != GCS_SYSTEM_ID:
            belief = ned_to_enu(np.array([message.x, message.y, message.z]))
            samples.pending[BELIEF][source] = belief
        elif kind == "SYSTEM_TIME" and source != GCS_SYSTEM_ID:
            samples.stamp(source, int(message.time_unix_usec))
        elif kind == "STATUSTEXT" and source != GCS_SYSTEM_ID:
            vehicle_texts.add(trace, source, message)
        elif kind == "TIMESYNC" and source != GCS_SYSTEM_ID:
            received_ns = round(message._timestamp * 1e9 - epoch * 1e9)
            replies.append(TimesyncReply(source, message.tc1, message.ts1, received_ns))
        elif source != GCS_SYSTEM_ID:
            continue
        elif kind == "VISION_POSITION_ESTIMATE":
            pending_estimate = (t, ned_to_enu(np.array([message.x, message.y, message.z])))
        elif kind == "SET_POSITION_TARGET_LOCAL_NED":
            _note_setpoint(trace, message, t, pending_estimate)
            pending_estimate = None
        elif kind == "SYSTEM_TIME" and message.time_boot_ms > 0:
            trace.ticks.add(round(message.time_boot_ms / 1000.0, 3))
        elif kind == "STATUSTEXT":
            text = chunks.add(message)
            if text is not None:
                _station_said(trace, text, t)
    offsets = {} if trace.ticks else clock_offsets(replies)
    epoch_usec = round(epoch * 1e6)
    kinds = (TRUTH, ATTITUDE, BELIEF, FIX)
    for kind, into in zip(kinds, (trace.truth, trace.attitudes, trace.beliefs, trace.fixes)):
        for system, stamp, position in samples.stamped[kind]:
            if trace.ticks or system in offsets:
                into[(system, truth_time(stamp, epoch_usec, offsets.get(system, 0.0)))] = position
    return trace


def _note_setpoint(
    trace: RunTrace, message: Any, t: float, estimate: tuple[float, np.ndarray] | None
) -> None:
    """A setpoint the ground station sent at ``t``, after ``estimate`` (None: none): the
    target, its velocity where it has one, and for the work UAV a cycle."""
    target = message.target_system
    trace.setpoints[(target, t)] = ned_to_enu(np.array([message.x, message.y, message.z]))
    if not message.type_mask & VELOCITY_IGNORED:
        velocity = np.array([message.vx, message.vy, message.vz])
        trace.setpoint_velocities[(target, t)] = ned_to_enu(velocity)
    if estimate is not None:
        trace.sent_estimates[(target, t)] = estimate[1]
    if target == 1:
        trace.cycles.add(t)
        if estimate is not None:
            trace.estimates[estimate[0]] = estimate[1]


class _VehicleTexts:
    """The vehicles' STATUSTEXTs, each vehicle's long ones put together from their chunks,
    each text taken once: it names its time, so the same text again is a copy (a step sent
    again carries what the vehicle said in it)."""

    def __init__(self) -> None:
        self._said: set[tuple[int, str]] = set()
        self._chunks: dict[int, StatusChunks] = {}

    def add(self, trace: RunTrace, source: int, message: Any) -> None:
        """A vehicle's contact or event into ``trace`` once its text is whole and new."""
        text = self._chunks.setdefault(source, StatusChunks()).add(message)
        if text is None or (source, text) in self._said:
            return
        self._said.add((source, text))
        contact = _CONTACT.match(text)
        if contact:
            trace.contacts.append(_contact_event(source, contact))
        event = parse_event(text, VehicleIdentity.from_system_id(source).name)
        if event is not None:
            trace.events.append(event)


def _station_said(trace: RunTrace, text: str, t: float) -> None:
    """What the ground station's STATUSTEXT at ``t`` tells: completion, the inspections'
    end, a stop, a link event."""
    if "Mission complete" in text:
        trace.completion = t if trace.completion is None else trace.completion
    elif text.startswith("Inspections complete"):
        trace.inspections_done = t
    elif text.startswith("Run stopped: "):
        trace.stopped = trace.stopped or f"{text[13:]} at {t:.1f} s"
    elif _LINK_EVENT.match(text):
        trace.link_events.append({"t": t, "event": text})


TRUTH, ATTITUDE, BELIEF, FIX = "truth", "attitude", "belief", "fix"


class _StepSamples:
    """Each vehicle's truth (SIM_STATE), belief (LOCAL_POSITION_NED) and GNSS fix (a 3-D
    GPS_RAW_INT) of a step, held until
    that step's SYSTEM_TIME marker stamps them: (system, stamp in usec, position)."""

    def __init__(self) -> None:
        kinds = (TRUTH, ATTITUDE, BELIEF, FIX)
        self.pending: dict[str, dict[int, np.ndarray]] = {kind: {} for kind in kinds}
        self.stamped: dict[str, list[tuple[int, int, np.ndarray]]] = {kind: [] for kind in kinds}

    def stamp(self, system: int, usec: int) -> None:
        """The step's marker: what ``system`` sent before it is stamped with ``usec``."""
        for kind, waiting in self.pending.items():
            if system in waiting:
                self.stamped[kind].append((system, usec, waiting.pop(system)))


def _contact_event(system: int, match: re.Match) -> dict[str, Any]:
    """A vehicle's contact report as summary.json holds it (its clock's time: in lockstep,
    the ground station's)."""
    vehicle = "work" if system == 1 else f"support-{system - 1}"
    kind, other, time_s, *where = match.groups()
    return {
        "t": float(time_s),
        "vehicle": vehicle,
        "with": other,
        "at_m": [float(v) for v in where],
        "crash": kind == "Crash",
    }


def _tlog_messages(tlog: Path) -> Iterator[Any]:
    """The messages of the kinds the metrics read, each with its ``_timestamp``.

    A tlog is (8-byte big-endian microseconds, MAVLink packet) records. The packet headers
    say each message's id and length, so the ~80 % of packets the metrics never read (GPS,
    camera, attitude, heartbeats, ...) are skipped without decoding. Anything that is not a
    well-formed MAVLink 2 record sends the whole file through pymavlink's tolerant reader.
    """
    data = tlog.read_bytes()
    records = _wanted_records(data)
    if records is None:
        yield from pymavlink_messages(tlog)
        return
    parser, fast = mavlink2.MAVLink(None), FastDecoder()
    for usec, packet in records:
        decoded = fast.decode(packet)  # pymavlink's objects, sooner; else pymavlink decides
        try:
            message = decoded[0] if decoded else parser.decode(bytearray(packet))
        except mavlink2.MAVError:
            continue  # a corrupt packet: the reference reader drops it too
        message._timestamp = usec * 1.0e-6
        yield message


def _wanted_records(data: bytes) -> list[tuple[int, bytes]] | None:
    """(microseconds, packet) of the wanted kinds, or None if ``data`` is not plain MAVLink 2."""
    records, end, clean = scan_records(data, _WANTED_IDS)
    return records if clean and end == len(data) else None


def scan_records(data: bytes, wanted: frozenset[int]) -> tuple[list[tuple[int, bytes]], int, bool]:
    """The (microseconds, packet) records of the ``wanted`` message ids in ``data``; the offset
    just past the last whole record; and whether everything up to it was well-formed MAVLink 2
    (a cut record at the end is not an error: a tlog still being written ends in one)."""
    records, offset, end = [], 0, len(data)
    while offset < end:
        begin = offset + 8
        if begin + 10 > end:
            break
        if data[begin] != mavlink2.PROTOCOL_MARKER_V2:
            return records, offset, False
        length = data[begin + 1]
        size = 10 + length + 2 + (13 if data[begin + 2] & mavlink2.MAVLINK_IFLAG_SIGNED else 0)
        if begin + size > end:
            break
        msgid = int.from_bytes(data[begin + 7 : begin + 10], "little")
        if msgid in wanted:
            usec = int.from_bytes(data[offset:begin], "big")
            records.append((usec, data[begin : begin + size]))
        offset = begin + size
    return records, offset, True


def zone_steps(trace: RunTrace, world: World) -> dict[int, list[float]]:
    """Per support system id, the control cycles at whose time its truth was inside a zone."""
    steps: dict[int, list[float]] = defaultdict(list)
    cycles = trace.cycle_times
    for system in trace.supports:
        positions, known = trace.truth_at(system, cycles)
        if not known.any():
            continue
        times = [t for t, k in zip(cycles, known) if k]
        inside = world.in_zone(positions[known])
        steps[system] = [t for t, hit in zip(times, inside) if hit]
    return steps


def work_errors(trace: RunTrace) -> tuple[np.ndarray, np.ndarray]:
    """(times, |xhat - x|) of the work UAV at every cycle with an estimate (not blind) whose
    truth is known."""
    times = sorted(trace.estimates)
    truth, known = trace.truth_at(1, times)
    estimates = np.array([trace.estimates[t] for t in times]).reshape(-1, 3)
    errors = np.linalg.norm(estimates[known] - truth[known], axis=1)
    return np.array(times)[known], errors


def trace_metrics(trace: RunTrace, world: World) -> dict[str, Any]:
    """The metrics of summary.json that a tlog determines, from its trace."""
    steps = zone_steps(trace, world)
    _, errors = work_errors(trace)
    counts = {f"support-{s - 1}": len(steps.get(s, [])) for s in trace.supports}
    return {
        "completed": trace.completion is not None,
        "completion_time_s": trace.completion,
        "stopped": trace.stopped,
        "control_cycles": len(trace.cycles),
        "multipath_steps": counts,
        "multipath_steps_total": int(sum(counts.values())),
        "work_error_m": spread([float(e) for e in errors]),
        **gnss_error_metrics(trace, world),
        "tracking_error_m": tracking_metrics(
            trace, world.scenario.control.s_max_work_m_s, world.scenario.control.s_max_support_m_s
        ),
        "link_events": trace.link_events,
        "events": sorted(trace.events, key=lambda e: (e["t"], e["vehicle"])),
        "safety": safety_metrics(trace, world),
    }


def mpc_stats(records: list[dict[str, Any]]) -> dict[str, float | None]:
    """Median and p95 of the support-MPC solve times in a run's records."""
    times = [m["ms"] for record in records for m in record["mpc"].values()]
    if not times:
        return {"median": None, "p95": None}
    return {
        "median": round(float(np.median(times)), 3),
        "p95": round(float(np.percentile(times, 95)), 3),
    }


def measurement_ages(records: list[dict[str, Any]]) -> dict[str, float | None]:
    """Median, p95 and max of the ages (ms) of the measurements the ground station used, from
    its records (real time; a lockstep record has no ages: every measurement it used was
    the step's own, age zero)."""
    if records and not any("age_ms" in record for record in records):  # lockstep
        return {"median": 0.0, "p95": 0.0, "max": 0.0}
    ages = [
        age
        for record in records
        for pair in record.get("age_ms", {}).values()
        for age in pair
        if age is not None
    ]
    if not ages:
        return {"median": None, "p95": None, "max": None}
    return {
        "median": round(float(np.median(ages)), 1),
        "p95": round(float(np.percentile(ages, 95)), 1),
        "max": round(float(np.max(ages)), 1),
    }
