"""One simulated multicopter: state, message handling, stepping and telemetry (no sockets).

The process around it (:mod:`vehicle_sim.server`) owns the sockets and the pacing and
calls :meth:`Vehicle.handle` for each message and :meth:`Vehicle.step` /
:meth:`Vehicle.publish` for each simulation step.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.random import default_rng as rng
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.config.autopilot_settings import PX4_PARAMETERS
from mission.config.settings import Scenario
from mission.config.wind_settings import WindSettings
from mission.link.mavlink_udp import LinkCounters
from mission.link.statustext import statustexts
from mission.link.vehicle_events import event_text, parameter_change
from mission.link.vehicle_identity import VehicleIdentity
from mission.world.contact_body import ContactBody
from mission.world.frames import GeodeticFrame
from mission.world.model import World
from mission.world.proximity import StructureProximity
from vehicle_sim.dynamics.clock import StepClock
from vehicle_sim.dynamics.contact import Contact, ContactDetector, ContactWatch, as_sent
from vehicle_sim.dynamics.motion import vehicle_motion
from vehicle_sim.mavlink import modes, streams, telemetry
from vehicle_sim.mavlink.auto_mission import fly_mission
from vehicle_sim.mavlink.guidance import fence_moving_target
from vehicle_sim.mavlink.incoming import HANDLERS
from vehicle_sim.mavlink.mission_server import MissionServer
from vehicle_sim.mavlink.param_server import ParamServer
from vehicle_sim.mavlink.parameters import vehicle_parameters
from vehicle_sim.mavlink.stream_schedule import StreamSchedule
from vehicle_sim.sensors import failures
from vehicle_sim.sensors.camera import Camera
from vehicle_sim.sensors.failures import SensorFailures
from vehicle_sim.sensors.fault_schedule import FaultInjector, FaultSchedule
from vehicle_sim.sensors.gnss_receiver import GnssReceiver


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
        gnss_rng, camera_rng, self.rng_motion, _, _, drift = map(rng, seeds)
        # the wind is the run's, the same field in every vehicle: from the seed alone
        self.kinematics = vehicle_motion(world, self.home, seed, drift)
        flying = scenario.vehicle.dynamics == "multicopter"  # its rims and frame strike things
        body = ContactBody.of(scenario.vehicle.multicopter) if flying else None
        proximity = StructureProximity(world.structure)
        detector = ContactDetector(proximity, scenario.vehicle.radius_m, body)
        self.watch = ContactWatch(detector, scenario.run.stop_on_crash)
        self._last_move = (as_sent(self.home), as_sent(self.home))  # the last step, as sent
        self.armed = False
        self.mode = modes.LOITER
        self.clock = StepClock(scenario.control.t_cont_s, scenario.run.epoch_unix_s)
        self.counters = LinkCounters()
        self.failsafe = False
        self.last_setpoint_s = 0.0
        self.last_warning = ("", -math.inf)  # the last warning said, and when
        self._wind_said: tuple[tuple[float, float, float], WindSettings] | None = None
        self._text_id = 0  # the last id of a STATUSTEXT sent in chunks
        self.last_estimate_usec: dict[tuple[int, int], int] = {}  # per sender: the last taken
        self.last_setpoint_seen: dict[tuple[int, int], tuple] = {}  # per sender: stamp, content
        vs = scenario.vehicle
        self.speed_limit_m_s = (
            scenario.control.s_max_work_m_s
            if identity.is_work
            else scenario.control.s_max_support_m_s
        )
        flying, camera = vs.dynamics == "multicopter", not identity.is_work
        self.schedule = StreamSchedule(vs, flying, camera)
        self.failures = SensorFailures(seeds[3], vs.sensor_hz)
        self.on_link_loss: Callable[[float], None] | None = None  # the process's socket, wired in
        self.mission, self.params = self._protocol_servers(speedup, link_loss)
        table = self.params.table
        self.gnss = GnssReceiver(world, self.frame, gnss_rng, table, self.failures)
        self.camera = Camera(world.camera, camera_rng, table, self.failures, carried=camera)
        schedule = FaultSchedule(scenario.faults, identity.name)
        self.faults = FaultInjector(schedule, table, self.inject_failure, self._parameter_set)

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
        params = ParamServer(table, self.send, self.notify, self._parameter_set, self._veto)
        return mission, params

    def _veto(self, name: str, value: float) -> str | None:
        """Why a flying vehicle's loops could not take ``value`` for PX4 parameter ``name``
        with the others as they are (a kinematic point takes any in range)."""
        if name in PX4_PARAMETERS and hasattr(self.kinematics, "tuning_problem"):
            return self.kinematics.tuning_problem(PX4_PARAMETERS[name], value)
        return None

    def _parameter_set(self, name: str, value: float, source: str = "Set") -> None:
        """A parameter set live takes effect before the next step, and is said. Most are read
        where they are used (the GNSS receiver, the camera, the failsafe, the motion)."""
        if name == "SIM_GPS1_ENABLE":  # as ArduPilot's: 0 turns the receiver off
            self.failures.inject(failures.GPS, failures.OK if value else failures.OFF)
        elif name == "SIM_GPS1_HZ":
            self.schedule.intervals_s[mavlink2.MAVLINK_MSG_ID_GPS_RAW_INT] = 1.0 / value
        elif name == "WPNAV_SPEED":
            self.speed_limit_m_s = value / 100.0
        elif name == "SIM_LINK_LOSS" and self.on_link_loss is not None:
            self.on_link_loss(value)
        elif name in PX4_PARAMETERS and hasattr(self.kinematics, "tune"):  # a multicopter's
            self.kinematics.tune(PX4_PARAMETERS[name], value)
        what = parameter_change(name, value)
        self.notify(mavlink2.MAV_SEVERITY_INFO, event_text(source, what, self.sim_time_s))

    def inject_failure(self, unit: int, kind: int, source: str = "Failure") -> bool:
        """Fail ``unit`` as ``kind`` (OK: healthy again) and say so; False if not offered."""
        if not self.failures.inject(unit, kind):
            return False
        what = failures.failure_name(unit, kind)
        self.notify(mavlink2.MAV_SEVERITY_WARNING, event_text(source, what, self.sim_time_s))
        return True

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
    def sim_time_s(self) -> float:
        """Simulated seconds since start."""
        return self.clock.sim_time_s

    def publish(self, work_truth: np.ndarray | None) -> None:
        """Send every stream that is due at the current simulated time, then SYSTEM_TIME."""
        for message_id in self.schedule.due(self.sim_time_s):
            message = self.build_stream(message_id, work_truth)
            if message is not None:  # None: a failed sensor publishes nothing
                self.send(message)
            self.schedule.sent(message_id, self.sim_time_s)
        clock = self.clock
        self.send(mavlink2.MAVLink_system_time_message(clock.time_unix_usec, clock.time_boot_ms))

    def sensor_due(self) -> bool:
        """True when this step's publish samples the camera (needs the work UAV's truth)."""
        return self.schedule.is_due(mavlink2.MAVLINK_MSG_ID_LANDING_TARGET, self.sim_time_s)

    def build_stream(self, message_id: int, work_truth: np.ndarray | None = None) -> Any:
        """Build one message of a stream for the current state (samples sensors when needed)."""
        return streams.build(self, message_id, work_truth)

    # -- stepping ---------------------------------------------------------------------------
    def step(self, others: dict[str, tuple[np.ndarray, np.ndarray]] | None = None) -> None:
        """Advance one step of simulated time: contacts with other vehicles over the step just
        ended (``others``: each one's true position at its start and end, as the truth channel
        carries them), failsafe check, mode logic, motion, contacts with the structure and
        the ground along the move."""
        step_s = self.clock.step_s
        if others:
            start_s = self.sim_time_s - step_s
            found = self.watch.detector.with_vehicles(
                self._last_move, others, start_s, self.sim_time_s
            )
            self._report(self.watch.new_contacts("vehicles", found))
        self._check_failsafe()
        if self.armed and self.mode == modes.AUTO:
            fly_mission(self)
        start, start_s = self.kinematics.truth.copy(), self.sim_time_s
        if self.armed and hasattr(self.kinematics, "set_wind"):  # a multicopter feels it
            self.kinematics.set_wind(self._wind_now(), self.sim_time_s)
        if self.armed:
            fence_moving_target(self.world, self.kinematics, step_s)
            self.kinematics.step(
                step_s,
                self.speed_limit_m_s,
                self.rng_motion,
                self.params.table.value("SIM_TRACK_NOISE"),
            )
        self.clock.advance()
        if self.armed:
            found = self.watch.detector.along(self.kinematics.path, start_s, self.sim_time_s)
            self._report(self.watch.new_contacts("surroundings", found))
        self._last_move = (as_sent(start), as_sent(self.kinematics.truth))
        self.faults.apply_due(self.sim_time_s)

    def _wind_now(self) -> WindSettings:
        """The scenario's wind as SIM_WIND_SPD, _DIR and _DRYDEN say it is now (made again
        only when one of them has changed)."""
        value = self.params.table.value
        said = tuple(value(name) for name in ("SIM_WIND_SPD", "SIM_WIND_DIR", "SIM_WIND_DRYDEN"))
        if self._wind_said is None or self._wind_said[0] != said:
            self._wind_said = (said, self._wind_of(said))
        return self._wind_said[1]

    def _wind_of(self, said: tuple[float, float, float]) -> WindSettings:
        speed, from_deg, turbulence = said
        return replace(
            self.scenario.world.wind,
            speed_m_s=speed,
            from_deg=from_deg % 360,
            turbulence=turbulence,
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
        self.clock.join(time_s)
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
