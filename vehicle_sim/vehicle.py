"""One simulated multicopter: state, message handling, stepping and telemetry (no sockets).

The process around it (:mod:`vehicle_sim.process.server`) owns the sockets and the clock and calls
:meth:`Vehicle.handle` for each message and :meth:`Vehicle.step` / :meth:`Vehicle.publish`
for each simulation step.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.random import default_rng as rng
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.config.settings import Scenario
from mission.config.wind_settings import WindSettings
from mission.link.mavlink_udp import LinkCounters
from mission.link.statustext import statustexts
from mission.link.vehicle_events import event_text, parameter_change
from mission.link.vehicle_identity import VehicleIdentity
from mission.world.frames import GeodeticFrame
from mission.world.model import World
from mission.world.proximity import StructureProximity
from vehicle_sim.dynamics.contact import Contact, ContactDetector, ContactWatch, as_sent
from vehicle_sim.dynamics.kinematics import Kinematics
from vehicle_sim.mavlink import modes, streams, telemetry
from vehicle_sim.mavlink.auto_mission import fly_mission
from vehicle_sim.mavlink.incoming import HANDLERS
from vehicle_sim.mavlink.mission_server import MissionServer
from vehicle_sim.mavlink.param_server import ParamServer
from vehicle_sim.mavlink.parameters import vehicle_parameters
from vehicle_sim.sensors import failures
from vehicle_sim.sensors.failures import SensorFailures
from vehicle_sim.sensors.fault_schedule import FaultSchedule
from vehicle_sim.sensors.gnss_receiver import GnssReceiver

GCS_SYSTEM_ID = 255
SENSOR_STREAMS = (
    mavlink2.MAVLINK_MSG_ID_SIM_STATE,
    mavlink2.MAVLINK_MSG_ID_LOCAL_POSITION_NED,
    mavlink2.MAVLINK_MSG_ID_GLOBAL_POSITION_INT,
    mavlink2.MAVLINK_MSG_ID_GPS_RAW_INT,
    mavlink2.MAVLINK_MSG_ID_LANDING_TARGET,
)
FLYING_STREAMS = (mavlink2.MAVLINK_MSG_ID_ATTITUDE,)  # a multicopter's, at the sensor rate
STATUS_STREAMS = (
    mavlink2.MAVLINK_MSG_ID_HEARTBEAT,
    mavlink2.MAVLINK_MSG_ID_SYS_STATUS,
    mavlink2.MAVLINK_MSG_ID_MISSION_CURRENT,
)


class Vehicle:
    """A work or support UAV with the paper's sensors and an autopilot's MAVLink behaviour."""

    def __init__(
        self,
        identity: VehicleIdentity,
        scenario: Scenario,
        world: World,
        home_enu: np.ndarray,
        seed: int,
        send: Callable[[Any], None],
        speedup: float = 1.0,
        link_loss: float = 0.0,
    ) -> None:
        self.identity = identity
        self.scenario = scenario
        self.world = world
        self.frame = GeodeticFrame(scenario.world.anchor)
        self.home = np.asarray(home_enu, dtype=float).reshape(3)
        self.send = send
        # a spawned child depends on its index only: each added one leaves the earlier as they were
        seeds = np.random.SeedSequence([seed, identity.instance]).spawn(6)
        self.rng_gnss, self.rng_camera, self.rng_motion, _, wind, drift = map(rng, seeds)
        self.kinematics = _motion(world, self.home, wind, drift)
        detector = ContactDetector(StructureProximity(world.structure), scenario.vehicle.radius_m)
        self.watch = ContactWatch(detector, scenario.run.stop_on_crash)
        self._last_move = (as_sent(self.home), as_sent(self.home))  # the last step, as sent
        self.armed = False
        self.mode = modes.LOITER
        self.sim_time_s = 0.0
        self.steps = 0
        self.counters = LinkCounters()
        self.failsafe = False
        self.last_setpoint_s = 0.0
        self.last_warning = ("", -math.inf)  # the last warning said, and when
        self._text_id = 0  # the last id of a STATUSTEXT sent in chunks
        self.last_estimate_usec: dict[tuple[int, int], int] = {}  # per sender: the last taken
        self.last_setpoint_seen: dict[tuple[int, int], tuple] = {}  # per sender: stamp, content
        vs = scenario.vehicle
        self.step_s = scenario.control.t_cont_s
        self.speed_limit_m_s = (
            scenario.control.s_max_work_m_s
            if identity.is_work
            else scenario.control.s_max_support_m_s
        )
        self.intervals_s: dict[int, float | None] = {
            **{m: 1.0 / vs.sensor_hz for m in SENSOR_STREAMS},
            mavlink2.MAVLINK_MSG_ID_HEARTBEAT: 1.0 / vs.heartbeat_hz,
            mavlink2.MAVLINK_MSG_ID_SYS_STATUS: 1.0 / vs.status_hz,
            mavlink2.MAVLINK_MSG_ID_MISSION_CURRENT: 1.0 / vs.status_hz,
        }
        if vs.dynamics == "multicopter":
            self.intervals_s.update({m: 1.0 / vs.sensor_hz for m in FLYING_STREAMS})
        if identity.is_work:  # the work UAV carries no camera looking at itself
            del self.intervals_s[mavlink2.MAVLINK_MSG_ID_LANDING_TARGET]
        self._default_intervals = dict(self.intervals_s)
        self._last_sent_s: dict[int, float] = {}
        self.failures = SensorFailures(seeds[3], vs.sensor_hz)
        self.on_link_loss: Callable[[float], None] | None = None  # the process's socket, wired in
        self.mission, self.params = self._protocol_servers(speedup, link_loss)
        self.gnss = GnssReceiver(world, self.frame, self.rng_gnss, self.params.table, self.failures)
        self.faults = FaultSchedule(scenario.faults, identity.name)
        self._before_fault: dict[int, float] = {}  # a parameter's value before its fault

    def _protocol_servers(
        self, speedup: float, link_loss: float
    ) -> tuple[MissionServer, ParamServer]:
        """The mission protocol's server and the parameter protocol's."""
        vs = self.scenario.vehicle
        mission = MissionServer(
            (self.identity.system_id, 1),
            self.send,
            self.notify,
            timeout_s=vs.mission_timeout_wall_s / speedup,
            retries=vs.mission_retries,
            capacity=vs.mission_capacity,
        )
        table = vehicle_parameters(self.scenario, self.speed_limit_m_s, speedup, link_loss)
        return mission, ParamServer(table, self.send, self.notify, self._parameter_set)

    def _parameter_set(self, name: str, value: float, source: str = "Set") -> None:
        """A parameter set live takes effect before the next step, and is said. Most are read
        where they are used (the GNSS receiver, the camera, the failsafe, the motion)."""
        if name == "SIM_GPS1_ENABLE":  # as ArduPilot's: 0 turns the receiver off
            self.failures.inject(failures.GPS, failures.OK if value else failures.OFF)
        elif name == "SIM_GPS1_HZ":
            self.intervals_s[mavlink2.MAVLINK_MSG_ID_GPS_RAW_INT] = 1.0 / value
        elif name == "WPNAV_SPEED":
            self.speed_limit_m_s = value / 100.0
        elif name == "SIM_LINK_LOSS" and self.on_link_loss is not None:
            self.on_link_loss(value)
        what = parameter_change(name, value)
        self.notify(mavlink2.MAV_SEVERITY_INFO, event_text(source, what, self.sim_time_s))

    def inject_failure(self, unit: int, kind: int, source: str = "Failure") -> bool:
        """Fail ``unit`` as ``kind`` (OK: healthy again) and say so; False if not offered."""
        if not self.failures.inject(unit, kind):
            return False
        what = failures.failure_name(unit, kind)
        self.notify(mavlink2.MAV_SEVERITY_WARNING, event_text(source, what, self.sim_time_s))
        return True

    def _apply_faults(self) -> None:
        """The scenario's faults due at this step boundary
        (:mod:`vehicle_sim.sensors.fault_schedule`)."""
        for change in self.faults.due(self.sim_time_s):
            fault = change.fault
            if fault.failure is not None:
                unit, kind = failures.parse_failure(fault.failure)
                self.inject_failure(unit, failures.OK if change.ends else kind, "Fault")
                continue
            table = self.params.table
            index = table.index_of(str(fault.param))
            assert index is not None  # the scenario's check: a catalogue id
            if change.ends:
                value = self._before_fault.pop(index)
            else:
                self._before_fault[index] = table[index].value
                value = float(fault.value)  # type: ignore[arg-type]
            table.set(index, value)
            self._parameter_set(table[index].name, value, "Fault")

    # -- outgoing ---------------------------------------------------------------------------
    def notify(self, severity: int, text: str) -> None:
        """Send a STATUSTEXT event; a text longer than its 50-byte field in chunks (MAVLink
        2's ``id`` and ``chunk_seq``), so that no refusal is cut short."""
        self._text_id = self._text_id % 65535 + 1
        for message in statustexts(text, self._text_id, severity):
            self.send(message)

    def heartbeat(self) -> Any:
        """The HEARTBEAT describing armed state and mode."""
        return telemetry.heartbeat(self.mode, self.armed, self.failsafe, self.crashed)

    @property
    def crashed(self) -> bool:
        """True once a contact has crashed this vehicle (it stays where it touched)."""
        return self.watch.crash is not None

    @property
    def time_boot_ms(self) -> int:
        """Simulated milliseconds since start."""
        return round(self.sim_time_s * 1000)

    @property
    def time_unix_usec(self) -> int:
        """Simulated time as UNIX microseconds from the scenario's epoch."""
        return round((self.scenario.run.epoch_unix_s + self.sim_time_s) * 1e6)

    def publish(self, work_truth: np.ndarray | None) -> None:
        """Send every stream that is due at the current simulated time, then SYSTEM_TIME."""
        due = {m for m, interval in self.intervals_s.items() if self._due(m, interval)}
        for message_id in (*SENSOR_STREAMS, *FLYING_STREAMS, *STATUS_STREAMS):
            if message_id in due:
                message = self.build_stream(message_id, work_truth)
                if message is not None:  # None: a failed sensor publishes nothing
                    self.send(message)
                self._last_sent_s[message_id] = self.sim_time_s
        self.send(mavlink2.MAVLink_system_time_message(self.time_unix_usec, self.time_boot_ms))

    def sensor_due(self) -> bool:
        """True when this step's publish samples the camera (needs the work UAV's truth)."""
        message_id = mavlink2.MAVLINK_MSG_ID_LANDING_TARGET
        return self._due(message_id, self.intervals_s.get(message_id))

    def _due(self, message_id: int, interval: float | None) -> bool:
        if interval is None:
            return False
        last = self._last_sent_s.get(message_id)
        return last is None or self.sim_time_s - last >= interval - 1e-6

    def build_stream(self, message_id: int, work_truth: np.ndarray | None = None) -> Any:
        """Build one message of a stream for the current state (samples sensors when needed)."""
        return streams.build(self, message_id, work_truth)

    def observe(self, work_truth: np.ndarray | None):
        """The camera's observation of the work UAV (not valid without its truth)."""
        from mission.world.camera import Observation

        if work_truth is None or self.identity.is_work:
            return Observation(False, None, math.nan)
        value = self.params.table.value
        return self.world.camera.observe(
            self.kinematics.truth,
            work_truth,
            self.rng_camera,
            range_m=value("SIM_CAM_RANGE"),
            noise_scale=value("SIM_CAM_NOISE"),
        )

    # -- stepping ---------------------------------------------------------------------------
    def step(self, others: dict[str, tuple[np.ndarray, np.ndarray]] | None = None) -> None:
        """Advance one step of simulated time: contacts with other vehicles over the step just
        ended (``others``: each one's true position at its start and end, as the truth channel
        carries them), failsafe check, mode logic, motion, contacts with the structure and
        the ground along the move."""
        if others:
            start_s = self.sim_time_s - self.step_s
            found = self.watch.detector.with_vehicles(
                self._last_move, others, start_s, self.sim_time_s
            )
            self._report(self.watch.new_contacts("vehicles", found))
        self._check_failsafe()
        if self.armed and self.mode == modes.AUTO:
            fly_mission(self)
        start, start_s = self.kinematics.truth.copy(), self.sim_time_s
        if self.armed and hasattr(self.kinematics, "set_wind"):  # a multicopter feels it
            self.kinematics.set_wind(self._wind_now())
        if self.armed:
            self.kinematics.step(
                self.step_s,
                self.speed_limit_m_s,
                self.rng_motion,
                self.params.table.value("SIM_TRACK_NOISE"),
            )
        self.steps += 1
        self.sim_time_s = self.steps * self.step_s
        if self.armed:
            found = self.watch.detector.along(self.kinematics.path, start_s, self.sim_time_s)
            self._report(self.watch.new_contacts("surroundings", found))
        self._last_move = (as_sent(start), as_sent(self.kinematics.truth))
        if len(self.faults):
            self._apply_faults()

    def _wind_now(self) -> WindSettings:
        """The scenario's wind as SIM_WIND_SPD, _DIR and _DRYDEN say it is now."""
        value = self.params.table.value
        return replace(
            self.scenario.world.wind,
            speed_m_s=value("SIM_WIND_SPD"),
            from_deg=value("SIM_WIND_DIR") % 360,
            turbulence=value("SIM_WIND_DRYDEN"),
        )

    def _report(self, contacts: list[Contact]) -> None:
        """Say what was touched; a crash stops the vehicle where it touched and disarms it."""
        for contact in contacts:
            crash = contact is self.watch.crash
            severity = mavlink2.MAV_SEVERITY_EMERGENCY if crash else mavlink2.MAV_SEVERITY_CRITICAL
            self.notify(severity, contact.text(crash))
            if crash:
                self.kinematics.stop_at(contact.position_m)
                self.armed = False
                self.failsafe = False

    def join_clock(self, time_s: float) -> None:
        """Take up a running clock before the first step: the next step ends at ``time_s``."""
        self.steps = max(0, round(time_s / self.step_s) - 1)
        self.sim_time_s = self.steps * self.step_s
        self.last_setpoint_s = self.sim_time_s

    def _check_failsafe(self) -> None:
        if not (self.armed and self.mode == modes.GUIDED) or self.failsafe:
            return
        limit = self.params.table.value("FS_GCS_TIMEOUT")  # the scenario's, unless set
        if self.sim_time_s - self.last_setpoint_s >= limit - 1e-9:
            self.failsafe = True
            self.kinematics.hold()
            self.notify(
                mavlink2.MAV_SEVERITY_CRITICAL, f"Failsafe: no setpoint for {limit:g} s, holding"
            )

    # -- incoming ---------------------------------------------------------------------------
    def handle(self, msg: Any, wall_now: float) -> None:
        """Act on one message from a ground station; never raises on bad content."""
        target = getattr(msg, "target_system", 0)
        if target not in (0, self.identity.system_id):
            self.counters.reject("for another system")
            return
        if self.mission.handle(msg, wall_now) or self.params.handle(msg):
            return
        handler = HANDLERS.get(msg.get_type())
        if handler is not None:
            handler(self, msg)

    # -- used by commands -------------------------------------------------------------------
    def arm(self, armed: bool) -> None:
        """Arm (hold here until told otherwise) or disarm."""
        if armed and not self.armed:
            self.kinematics.hold()
            self.last_setpoint_s = self.sim_time_s
        self.armed = armed
        self.failsafe = False
        self.notify(mavlink2.MAV_SEVERITY_INFO, "Armed" if armed else "Disarmed")

    def change_mode(self, mode: int) -> None:
        """Enter a supported mode."""
        if mode != self.mode:
            self.mode = mode
            if mode in (modes.LOITER, modes.GUIDED):
                self.kinematics.hold()
            self.last_setpoint_s = self.sim_time_s
            self.failsafe = False
            self.notify(mavlink2.MAV_SEVERITY_INFO, f"Mode {modes.NAMES[mode]}")

    def set_interval(self, message_id: int, interval_us: float) -> bool:
        """SET_MESSAGE_INTERVAL: -1 stops, 0 restores the default; False if not a stream."""
        if message_id not in self._default_intervals:
            return False
        if interval_us < 0:
            self.intervals_s[message_id] = None
        elif interval_us == 0:
            self.intervals_s[message_id] = self._default_intervals[message_id]
        else:
            self.intervals_s[message_id] = interval_us / 1e6
        return True


def _motion(
    world: World, home: np.ndarray, wind_rng: np.random.Generator, drift_rng: np.random.Generator
) -> Any:
    """How the vehicle moves: the kinematic point (the default) or the flying quadrotor in the
    scenario's wind (imported only then: casadi is no small import for a vehicle that does
    not need it)."""
    scenario = world.scenario
    if scenario.vehicle.dynamics == "multicopter":
        from mission.world.surfaces import VerticalSurfaces
        from vehicle_sim.dynamics.multicopter import Multicopter

        return Multicopter.at(
            home,
            scenario.vehicle,
            scenario.control.t_cont_s,
            scenario.world.wind,
            list(world.structure.boxes),
            wind_rng,
            drift_rng,
            VerticalSurfaces(world.structure),
        )
    return Kinematics.at(home)
