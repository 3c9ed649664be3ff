"""The ground-station process: set up, then one control cycle every t_cont until the work UAV
reaches its last waypoint or the scenario's timeout.

Its pieces: the links to the vehicles (:mod:`~ground_station.links.vehicle_links`) and the
clock (:mod:`~ground_station.links.clock`), the messages it sends
(:mod:`~ground_station.links.outgoing`), what it writes (:mod:`~ground_station.records`,
:mod:`~ground_station.links.tlog`), the run's context built once (the map G, the support MPC:
:mod:`~ground_station.control.run_context`) and the cycle itself
(:mod:`~ground_station.control.cycle`).
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ground_station.control.cycle import CycleDecision, CycleOutput, complete_cycle, control_cycle
from ground_station.control.run_context import RunContext, build_run_context, require_known_world
from ground_station.estimation.localize import SupportReport, gnss_fix, reports_from_messages
from ground_station.links.clock import LockstepTiming, PendingStep, StationClock, await_step
from ground_station.links.outgoing import (
    mission_set_current,
    position_target,
    vision_position_estimate,
)
from ground_station.links.tlog import TlogWriter
from ground_station.links.vehicle_links import VehicleLinks
from ground_station.preflight import arm_all, connect, upload_missions
from ground_station.records import SNAPSHOT_EVERY, RunRecords
from ground_station.roles.allocation import inspections_left
from ground_station.state.station_state import StationState
from ground_station.support_mpc.sharing import MpcHelper
from mission.config.run_outputs import GSnapshots
from mission.link.impairment import LinkSettings
from mission.link.mavlink_udp import Address
from mission.procs.process_life import freeze_startup_heap
from mission.world.frames import GeodeticFrame
from mission.world.model import KnownWorld


@dataclass(frozen=True)
class StationConfig:
    """How this ground station runs."""

    adaptive: bool
    vehicles: dict[str, Address]
    waypoints_dir: Path
    out_dir: Path
    seed: int = 0
    speedup: float | None = None  # None: lockstep
    tlog_path: Path | None = None  # default: out_dir / "gcs.tlog"
    signing_key: bytes | None = None  # MAVLink 2 signing secret
    link: LinkSettings = field(default_factory=LinkSettings)  # loss and delay of what we send
    step_timeout_wall_s: float = 15.0  # a vehicle's step waited for (then it is late)
    late_grace_wall_s: float = 0.05  # lockstep: how long a late vehicle is waited for
    link_loss_s: float = 3.0  # simulated seconds of silence before a vehicle counts as lost
    link_loss_wall_s: float = 2.0  # real time: and at least this much wall time (a busy CPU)
    connect_timeout_wall_s: float = 30.0
    g_snapshots: GSnapshots = "every"  # which snapshots of G are written (records.py)
    mpc_helper: bool = False  # share the support MPCs with a helper process (second core)

    @property
    def silence_limit_s(self) -> float:
        """Simulated seconds of silence before a vehicle counts as lost: ``link_loss_s``, and
        in real time never less than ``link_loss_wall_s`` of wall time (at 10x, 3 s of
        simulated time is 0.3 s of wall time, less than a busy machine's scheduling stall)."""
        if self.speedup is None:
            return self.link_loss_s
        return max(self.link_loss_s, self.link_loss_wall_s * self.speedup)


def _all_done(state: StationState, context: RunContext | None) -> bool:
    """The work UAV's task is complete and no support has inspection waypoints left."""
    return state.completed and not (
        context is not None and inspections_left(state.allocation, context)
    )


class GroundStation:
    """Runs one mission over MAVLink and logs everything."""

    def __init__(self, world: KnownWorld, config: StationConfig) -> None:
        self.world = require_known_world(world)
        self.scenario = world.scenario
        self.config = config
        self.frame = GeodeticFrame(self.scenario.world.anchor)
        self.clock = StationClock(self.scenario.run, self.scenario.control.t_cont_s, config.speedup)
        self.timing = LockstepTiming(
            retry_wall_s=0.02 + 2 * config.link.delay_ms / 1000.0,
            step_timeout_wall_s=config.step_timeout_wall_s,
            late_grace_wall_s=config.late_grace_wall_s,
        )
        config.out_dir.mkdir(parents=True, exist_ok=True)
        self.tlog = TlogWriter(config.tlog_path or config.out_dir / "gcs.tlog")
        self.records = RunRecords(config.out_dir, config.g_snapshots)
        self.links = VehicleLinks(
            config.vehicles, self.clock, self.tlog, config.signing_key, config.link, config.seed
        )
        self.cycles = 0
        self.stopped: str | None = None  # why the run ended before its task (a crash)
        self.context: RunContext | None = None
        self._helper: MpcHelper | None = None

    def run(self) -> dict[str, Any]:
        """Connect, upload, arm, then cycle until done or timeout; return a summary."""
        start_wall = time.monotonic()
        context, state = self._set_up()
        self.records.snapshot(context.g, "initial")
        self.links.reset_loss_count()
        completion = self._fly(context, state)
        self.records.snapshot(context.g, "final")
        self.tlog.flush()
        self.records.link_stats(self.links.report(self.config.link))
        return {
            "completed": completion is not None and self.stopped is None,  # a crash fails it
            "completion_time_s": completion,
            "stopped": self.stopped,
            "control_cycles": self.cycles,
            "sim_time_s": self.clock.time_s,
            "wall_time_s": time.monotonic() - start_wall,
        }

    def _set_up(self) -> tuple[RunContext, StationState]:
        """The MPC helper started, the vehicles found, their missions uploaded, GUIDED and
        armed; the context built."""
        if self.config.mpc_helper:  # it imports while sigma_0 is computed here
            self._helper = MpcHelper(str(self.config.out_dir))
        sigma0 = self.world.sigma0_map().sigma_m
        if self._helper is not None:  # and builds its solver while we connect
            try:
                self._helper.set_up(self.scenario, sigma0)
            except OSError:
                print("ground station: MPC helper did not start; solving here", file=sys.stderr)
                self._helper.close()
                self._helper = None
        connect(self.links, self.config.connect_timeout_wall_s)
        waypoints = upload_missions(
            self.links, self.config.waypoints_dir, self.frame, self.timing.retry_wall_s
        )
        arm_all(self.links, self.timing.retry_wall_s)
        config = self.config
        self.context, state = build_run_context(
            self.world, waypoints, config.adaptive, config.seed, self._helper, sigma0
        )
        freeze_startup_heap()
        return self.context, state

    def _fly(self, context: RunContext, state: StationState) -> float | None:
        """Control cycles until the work UAV completes its task and the supports their
        inspections, or the timeout; the time the work UAV's task was complete."""
        self.clock.begin_flight()
        completion: float | None = None  # when the work UAV completed its task
        pending = self._start_step(self.clock.next_step())
        self.links.flush_all()
        while pending is not None:
            if not self.clock.lockstep:  # each vehicle's clock, for its measurements' ages
                self.links.sync_clocks()
            await_step(self.links, self.clock, pending, self.timing)
            if self._crashed():
                return None
            for name in self.links.supervise(self.config.silence_limit_s, self.clock.step_s):
                state.forget(name)
                if context.integrity is not None:
                    context.integrity.forget(name)
            reports = reports_from_messages(self.links.support_samples(), self.frame)
            decision = control_cycle(state, reports, context, self._work_fix())
            for event in decision.integrity.events if decision.integrity else ():
                self.links.announce(event.text)
            work_step = self._command_work(state, decision)  # it steps while
            output = complete_cycle(state, decision, context)  # the supports' MPCs are solved
            self._command_supports(state, output)
            cycle_time_s = self.clock.time_s
            done = _all_done(state, context)
            if state.completed and completion is None and not done:  # inspections go on
                completion = self._announce_completion()
            # the next tick goes out now: the vehicles step while this cycle is written down
            pending = None if done else self._start_step(work_step, work_ticked=True)
            self.links.flush_all()
            self._record(context, state, output, cycle_time_s, self._ages_ms(reports))
            if done:
                if completion is None:
                    completion = self._announce_completion()
                if context.inspections:
                    self.links.announce(f"Inspections complete at {cycle_time_s:.1f} s")
                return completion
        return completion

    def _announce_completion(self) -> float:
        """Say the work UAV's task is complete (now); its time."""
        self.links.announce(f"Mission complete at {self.clock.time_s:.1f} s")
        return self.clock.time_s

    def _work_fix(self) -> np.ndarray | None:
        """The work UAV's own 3-D fix of this cycle (ENU), where the roles are dynamic (the
        paper's fixed roles never read it)."""
        if self.scenario.roles.policy != "dynamic":
            return None
        message = self.links.current("work", "GPS_RAW_INT")
        if self.links.age_s("work", message) is None:
            return None
        return gnss_fix(message, self.frame)

    def _crashed(self) -> bool:
        """A vehicle said it crashed and the run stops on crashes: the run ends, failed."""
        crashes = [(v.name, v.crash) for v in self.links.views.values() if v.crash]
        if not crashes or not self.scenario.run.stop_on_crash:
            return False
        name, text = crashes[0]
        self.stopped = f"{name} crashed ({text})"
        self.links.announce(f"Run stopped: {name} crashed", to_stderr=True)
        return True

    def _start_step(self, step: PendingStep | None, work_ticked: bool = False):
        """Start ``step`` (None: none is left): in lockstep the clock advances and each
        vehicle's tick is queued after its commands, the work vehicle's unless it went out with
        its command (``work_ticked``)."""
        if step is None or step.tick is None:
            return step
        self.clock.start(step)
        for view in self.links.views.values():
            if not (work_ticked and view.name == "work"):
                self.links.queue_for(step.tick, view)
        return step

    def _command_work(self, state: StationState, decision: CycleDecision) -> PendingStep | None:
        """The work vehicle's estimate, setpoint (and the next mission item once a waypoint is
        reached) and, unless the mission is complete, the next step's tick, sent before the
        supports' MPCs are solved: it steps meanwhile, and its truth is there when the supports
        step. Returns the step its tick starts (None: no tick went out)."""
        links, work = self.links, self.links.views["work"]
        if not decision.blind:  # blind, it navigates on its own dead reckoning
            links.queue_for(vision_position_estimate(state.xhat, self.clock.time_usec), work)
        self._announce_sight(state, decision.blind)
        time_ms = round(self.clock.time_s * 1000)
        setpoint = self._setpoint(state.xhat, decision.work_command, time_ms, work.system_id)
        links.queue_for(setpoint, work)
        if decision.arrived is not None and not state.completed:
            links.queue_for(mission_set_current(work.system_id, state.k + 1), work)
            links.announce(f"Work UAV reached waypoint {decision.arrived + 1}")
        step = None if _all_done(state, self.context) else self.clock.next_step()
        if step is not None and step.tick is not None:
            links.queue_for(step.tick, work)
        links.flush(work)
        return step

    def _announce_sight(self, state: StationState, blind: bool) -> None:
        """STATUSTEXT when the work UAV goes blind (it holds) and when it is seen again."""
        if blind and state.blind_cycles == 0:
            self.links.announce("Work UAV blind: holding")
        elif not blind and state.blind_cycles > 0:
            self.links.announce(f"Work UAV seen again after {state.blind_cycles} blind cycles")
        state.blind_cycles = state.blind_cycles + 1 if blind else 0

    def _command_supports(self, state: StationState, output: CycleOutput) -> None:
        time_ms = round(self.clock.time_s * 1000)
        for name, target in output.support_targets.items():
            view = self.links.views[name]
            estimate = vision_position_estimate(state.yhat[name], self.clock.time_usec)
            self.links.queue_for(estimate, view)
            setpoint = self._setpoint(state.yhat[name], target, time_ms, view.system_id)
            self.links.queue_for(setpoint, view)

    def _setpoint(self, start: np.ndarray, command: np.ndarray, time_ms: int, system_id: int):
        """A UAV's SET_POSITION_TARGET_LOCAL_NED for a plan from ``start`` whose first point
        is ``command``: that point (a kinematic vehicle's interface), or, for a flying
        quadrotor with ``control.velocity_feedforward``, ``start`` and the plan's velocity
        (the target moves on at it, and the autopilot feeds it forward)."""
        scenario = self.context.scenario
        if scenario.vehicle.dynamics != "multicopter" or not scenario.control.velocity_feedforward:
            return position_target(command, time_ms, system_id)
        velocity = (np.asarray(command) - np.asarray(start)) / scenario.control.t_pred_s
        return position_target(start, time_ms, system_id, velocity)

    def _ages_ms(self, reports: list[SupportReport]) -> dict[str, list[float | None]] | None:
        """Real time: each support's [GNSS fix, camera observation] age in ms (None: not
        used); lockstep: None (every measurement is the step's own)."""
        if self.clock.lockstep:
            return None
        return {
            r.name: [
                None if r.fix is None else round(r.fix_age_s * 1000, 1),
                None if r.relative is None else round(r.relative_age_s * 1000, 1),
            ]
            for r in reports
        }

    def _record(
        self,
        context: RunContext,
        state: StationState,
        output: CycleOutput,
        time_s: float,
        ages_ms: dict[str, list[float | None]] | None,
    ) -> None:
        self.records.cycle(state, output, time_s, ages_ms)
        self.cycles += 1
        if self.cycles % SNAPSHOT_EVERY == 0:
            self.records.snapshot(context.g, f"{self.cycles:05d}")
        self.tlog.flush()

    def close(self) -> None:
        """Stop the MPC helper; flush and close every file and the socket."""
        if self.context is not None:
            self.context.planner.close()
        elif self._helper is not None:
            self._helper.close()
        self.tlog.close()
        self.records.close()
        self.links.close()
