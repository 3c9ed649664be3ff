"""One simulated multicopter: state, message handling, stepping and telemetry (no sockets).

The process around it (:mod:`vehicle_sim.server`) owns the sockets and the clock and calls
:meth:`Vehicle.handle` for each message and :meth:`Vehicle.step` / :meth:`Vehicle.publish`
for each simulation step.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, ClassVar

import numpy as np
from pymavlink.dialects.v20 import ardupilotmega as mavlink2

from mission.config.settings import Scenario
from mission.link.mavlink_udp import LinkCounters
from mission.link.mission_items import GLOBAL_FRAMES, NAV_POSITION_COMMANDS
from mission.link.vehicle_identity import VehicleIdentity
from mission.world.frames import GeodeticFrame, ned_to_enu
from mission.world.model import World
from mission.world.proximity import StructureProximity
from vehicle_sim import failures, modes, streams, telemetry
from vehicle_sim.commands import execute, set_mode
from vehicle_sim.contact import Contact, ContactDetector, ContactWatch, as_sent
from vehicle_sim.failures import SensorFailures
from vehicle_sim.guidance import MAX_ABS_COORD_M, geofence_problem, setpoint_problem
from vehicle_sim.kinematics import Kinematics
from vehicle_sim.mission_server import MissionServer
from vehicle_sim.param_server import ParamServer
from vehicle_sim.parameters import vehicle_parameters

GCS_SYSTEM_ID = 255
SENSOR_STREAMS = (
    mavlink2.MAVLINK_MSG_ID_SIM_STATE,
    mavlink2.MAVLINK_MSG_ID_LOCAL_POSITION_NED,
    mavlink2.MAVLINK_MSG_ID_GLOBAL_POSITION_INT,
    mavlink2.MAVLINK_MSG_ID_GPS_RAW_INT,
    mavlink2.MAVLINK_MSG_ID_LANDING_TARGET,
)
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
    ) -> None:
        self.identity = identity
        self.scenario = scenario
        self.world = world
        self.frame = GeodeticFrame(scenario.world.anchor)
        self.home = np.asarray(home_enu, dtype=float).reshape(3)
        self.send = send
        # the fourth child is new: the first three are what they always were
        gnss_seed, camera_seed, motion_seed, failure_seed = np.random.SeedSequence(
            [seed, identity.instance]
        ).spawn(4)
        self.rng_gnss = np.random.default_rng(gnss_seed)
        self.rng_camera = np.random.default_rng(camera_seed)
        self.rng_motion = np.random.default_rng(motion_seed)
        self.kinematics = Kinematics.at(self.home)
        detector = ContactDetector(StructureProximity(world.structure), scenario.vehicle.radius_m)
        self.watch = ContactWatch(detector, scenario.run.stop_on_crash)
        self._last_move = (as_sent(self.home), as_sent(self.home))  # the last step, as sent
        self.armed = False
        self.mode = modes.LOITER
        self.sim_time_s = 0.0
        self.steps = 0
        self.counters = LinkCounters()
        self.failsafe = False
        self._last_setpoint_s = 0.0
        self._last_warning = ""
        self._last_warning_s = -math.inf
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
        if identity.is_work:  # the work UAV carries no camera looking at itself
            del self.intervals_s[mavlink2.MAVLINK_MSG_ID_LANDING_TARGET]
        self._default_intervals = dict(self.intervals_s)
        self._last_sent_s: dict[int, float] = {}
        self.failures = SensorFailures(failure_seed, vs.sensor_hz)
        self.mission, self.params = self._protocol_servers(speedup)

    def _protocol_servers(self, speedup: float) -> tuple[MissionServer, ParamServer]:
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
        table = vehicle_parameters(self.scenario, self.speed_limit_m_s, speedup)
        return mission, ParamServer(table, self.send, self.notify, self._parameter_set)

    def _parameter_set(self, name: str, value: float) -> None:
        """A parameter set live takes effect (before the next step)."""
        if name == "SIM_GPS1_ENABLE":  # as ArduPilot's: 0 turns the receiver off
            kind = failures.OK if value else failures.OFF
            self.failures.inject(failures.GPS, kind)

    # -- outgoing ---------------------------------------------------------------------------
    def notify(self, severity: int, text: str) -> None:
        """Send a STATUSTEXT event."""
        self.send(telemetry.statustext(severity, text))

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
        for message_id in (*SENSOR_STREAMS, *STATUS_STREAMS):
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
        return self.world.camera.observe(self.kinematics.truth, work_truth, self.rng_camera)

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
            self._fly_mission()
        start, start_s = self.kinematics.truth.copy(), self.sim_time_s
        if self.armed:
            self.kinematics.step(
                self.step_s,
                self.speed_limit_m_s,
                self.rng_motion,
                self.scenario.vehicle.tracking_noise_m,
            )
        self.steps += 1
        self.sim_time_s = self.steps * self.step_s
        if self.armed:
            found = self.watch.detector.with_surroundings(
                start, self.kinematics.truth, start_s, self.sim_time_s
            )
            self._report(self.watch.new_contacts("surroundings", found))
        self._last_move = (as_sent(start), as_sent(self.kinematics.truth))

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
        self._last_setpoint_s = self.sim_time_s

    def _check_failsafe(self) -> None:
        if not (self.armed and self.mode == modes.GUIDED) or self.failsafe:
            return
        limit = self.params.table.value("FS_GCS_TIMEOUT")  # the scenario's, unless set
        if self.sim_time_s - self._last_setpoint_s >= limit - 1e-9:
            self.failsafe = True
            self.kinematics.hold()
            self.notify(
                mavlink2.MAV_SEVERITY_CRITICAL, f"Failsafe: no setpoint for {limit:g} s, holding"
            )

    def _fly_mission(self) -> None:
        items = self.mission.items
        current = self.mission.current
        if not items:
            return
        if current == 0 and len(items) > 1:
            self.mission.set_current(1)
            current = 1
        item = items[current]
        if item.command not in NAV_POSITION_COMMANDS or item.frame not in GLOBAL_FRAMES:
            if current + 1 < len(items):
                self.mission.set_current(current + 1)
            return
        target = self.item_position(item)
        self.kinematics.target = target
        acceptance = item.param2 if item.param2 > 0 else self.scenario.control.arrival_tol_m
        if np.linalg.norm(target - self.kinematics.believed) < acceptance:
            if current + 1 < len(items):
                self.mission.set_current(current + 1)
            else:
                self.send(mavlink2.MAVLink_mission_item_reached_message(current))
                self.mode = modes.LOITER
                self.kinematics.hold()
                self.notify(mavlink2.MAV_SEVERITY_INFO, "Mission complete, holding")

    def item_position(self, item) -> np.ndarray:
        """ENU position of a global mission item (relative altitudes from the anchor)."""
        alt = item.z
        if item.frame in (
            mavlink2.MAV_FRAME_GLOBAL_RELATIVE_ALT,
            mavlink2.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
        ):
            alt += self.scenario.world.anchor.alt_m
        return self.frame.from_degE7(item.x, item.y, alt)

    # -- incoming ---------------------------------------------------------------------------
    def handle(self, msg: Any, wall_now: float) -> None:
        """Act on one message from a ground station; never raises on bad content."""
        target = getattr(msg, "target_system", 0)
        if target not in (0, self.identity.system_id):
            self.counters.reject("for another system")
            return
        if self.mission.handle(msg, wall_now) or self.params.handle(msg):
            return
        handler = self._HANDLERS.get(msg.get_type())
        if handler is not None:
            handler(self, msg)

    def _on_setpoint(self, msg: Any) -> None:
        if self.crashed:
            self.counters.reject("setpoint: crashed")
            return
        problem = setpoint_problem(msg, self.armed and self.mode == modes.GUIDED)
        target = ned_to_enu(np.array([msg.x, msg.y, msg.z], dtype=float))
        if problem is None:
            problem = geofence_problem(self.world, self.kinematics.believed, target)
            if problem is not None:  # a guided vehicle told to leave the fence stops there
                self.kinematics.hold()
        if problem is not None:
            category, detail = problem
            self.counters.reject(f"setpoint: {category}")
            self._warn_once(f"Setpoint rejected: {detail}")
            return
        self.kinematics.target = target
        self._last_setpoint_s = self.sim_time_s
        if self.failsafe:
            self.failsafe = False
            self.notify(mavlink2.MAV_SEVERITY_NOTICE, "Failsafe cleared: setpoints resumed")

    def _warn_once(self, text: str) -> None:
        """A warning STATUSTEXT, not repeated while the same problem persists (5 s)."""
        if text != self._last_warning or self.sim_time_s - self._last_warning_s >= 5.0:
            self.notify(mavlink2.MAV_SEVERITY_WARNING, text)
            self._last_warning, self._last_warning_s = text, self.sim_time_s

    def _on_vision_estimate(self, msg: Any) -> None:
        values = (msg.x, msg.y, msg.z)
        if not all(math.isfinite(v) and abs(v) < MAX_ABS_COORD_M for v in values):
            self.counters.reject("estimate out of range")
            return
        self.kinematics.set_estimate(ned_to_enu(np.array(values, dtype=float)))

    def _on_command(self, msg: Any) -> None:
        params = [msg.param1, msg.param2, msg.param3, msg.param4]
        if msg.get_type() == "COMMAND_LONG":
            params += [msg.param5, msg.param6, msg.param7]
        else:
            params += [msg.x, msg.y, msg.z]
        result = execute(self, int(msg.command), params)
        self.send(
            mavlink2.MAVLink_command_ack_message(
                msg.command, result, 0, 0, msg.get_srcSystem(), msg.get_srcComponent()
            )
        )

    def _on_set_mode(self, msg: Any) -> None:
        result = set_mode(self, int(msg.base_mode), int(msg.custom_mode))
        self.send(
            mavlink2.MAVLink_command_ack_message(
                mavlink2.MAVLINK_MSG_ID_SET_MODE,
                result,
                0,
                0,
                msg.get_srcSystem(),
                msg.get_srcComponent(),
            )
        )

    def _on_timesync(self, msg: Any) -> None:
        if msg.tc1 == 0:
            now_ns = round(self.sim_time_s * 1e9)
            self.send(mavlink2.MAVLink_timesync_message(now_ns, msg.ts1))

    _HANDLERS: ClassVar[dict[str, Callable[[Vehicle, Any], None]]] = {
        "SET_POSITION_TARGET_LOCAL_NED": _on_setpoint,
        "VISION_POSITION_ESTIMATE": _on_vision_estimate,
        "COMMAND_LONG": _on_command,
        "COMMAND_INT": _on_command,
        "SET_MODE": _on_set_mode,
        "TIMESYNC": _on_timesync,
    }

    # -- used by commands -------------------------------------------------------------------
    def arm(self, armed: bool) -> None:
        """Arm (hold here until told otherwise) or disarm."""
        if armed and not self.armed:
            self.kinematics.hold()
            self._last_setpoint_s = self.sim_time_s
        self.armed = armed
        self.failsafe = False
        self.notify(mavlink2.MAV_SEVERITY_INFO, "Armed" if armed else "Disarmed")

    def change_mode(self, mode: int) -> None:
        """Enter a supported mode."""
        if mode != self.mode:
            self.mode = mode
            if mode in (modes.LOITER, modes.GUIDED):
                self.kinematics.hold()
            self._last_setpoint_s = self.sim_time_s
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
