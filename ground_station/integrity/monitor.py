"""The integrity monitor's state machine: each cycle, each support's statistics
(:mod:`~ground_station.integrity.consistency`) against their gates; a support excluded while
they say its receiver lies, restored once they say it does not.

- **Gates.** A test's statistics over the last m cycles in a row (m = 1 .. ``sustain_cycles``)
  sum to a chi-square of 3m degrees of freedom without a fault; the support is excluded when
  one such sum exceeds its gate at ``false_alarm``: a large step at once, a smaller bias once
  it has persisted. A statistic above the *suspect* gate (at ``false_alarm ** 0.5``) withholds
  the fix for that cycle without excluding the support: a step not yet confirmed is neither
  fused nor taken into the support's estimate, so the next cycle tests it again against the
  same reference rather than a reference that has already moved to it.
- **Identifying the liar.** The formation test of a support compares it with the other
  trusted supports (not excluded, their motion test passed). Where several exceed, with three
  or more trusted the largest is blamed if the others then agree; with two, the one whose
  motion test is suspect. Otherwise the monitor cannot tell: every support involved is
  withheld that cycle (none excluded), and, with no other support, the work UAV holds.
- **Recovery.** An excluded support is tested against its own reference (the formation's
  estimate, or dead reckoning): after ``recovery_cycles`` cycles in a row with every
  statistic under the suspect gate it is restored.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Sequence

import numpy as np

from ground_station.estimation.fusion import FusionResult, SupportMeasurement
from ground_station.estimation.gnss_map import LocalizabilityMap
from ground_station.integrity.aftermath import learn_excluded, settle
from ground_station.integrity.consistency import Formation, Innovation, motion_innovation
from ground_station.integrity.protection import (
    detectable_bias,
)
from ground_station.integrity.verdict import Event, Verdict, Watch
from ground_station.state.station_state import StationState
from mission.config.integrity_settings import IntegritySettings
from mission.maths.chi_square import detectable_noncentrality, gate

SUSPECT_EXPONENT = 0.5  # the suspect gate's false-alarm rate is false_alarm ** this
TESTS = ("motion", "formation")


class IntegrityMonitor:
    """Tests every support's fix each cycle (:meth:`check`) and keeps each one's covariance
    and state (:meth:`settle`, after the fusion)."""

    def __init__(
        self,
        settings: IntegritySettings,
        multicopter: bool,
        voxel_m: float,
        camera: Callable[[np.ndarray], np.ndarray] | None = None,
    ) -> None:
        self.settings = settings
        self.camera = camera  # Sigma_r of a relative vector (the formation test's)
        self.voxel_m = voxel_m  # G's resolution: a place finer than this is one place
        self.motion_sigma_m = (
            settings.motion_sigma_multicopter_m if multicopter else settings.motion_sigma_m
        )
        self.gates = [
            gate(settings.false_alarm, 3 * m) for m in range(1, settings.sustain_cycles + 1)
        ]
        self.suspect_gate = gate(settings.false_alarm**SUSPECT_EXPONENT, 3)
        self.detectable = detectable_noncentrality(settings.false_alarm, settings.missed_detection)
        self.k2 = gate(settings.missed_detection, 3)  # the no-fault radius's quantile
        self.fault_detectable = fault_noncentrality(settings)
        self.watches: dict[str, Watch] = {}
        self.formation = Formation([])  # the cycle's supports' information (check, then settle)

    def watch(self, name: str) -> Watch:
        """The support's watch (made at its first cycle)."""
        if name not in self.watches:
            self.watches[name] = Watch()
        return self.watches[name]

    def forget(self, name: str) -> None:
        """A support that fell silent and is back starts afresh."""
        self.watches.pop(name, None)

    def check(self, measurements: Sequence[SupportMeasurement], state: StationState) -> Verdict:
        """The cycle's tests of every support's fix (before the fusion)."""
        motion = {m.name: self._motion(m, state) for m in measurements}
        suspect_motion = {
            n for n, found in motion.items() if found and found.statistic > self.suspect_gate
        }
        recorded, decisive, ambiguous = self._formation(measurements, suspect_motion)
        statistics: dict[str, dict[str, float]] = {}
        events: list[Event] = []
        withheld = set(ambiguous)
        for m in measurements:
            shown = {"motion": motion[m.name], "formation": recorded.get(m.name)}
            statistics[m.name] = {test: f.statistic for test, f in shown.items() if f is not None}
            found = {"motion": motion[m.name], "formation": decisive.get(m.name)}
            present = {test: f for test, f in found.items() if f is not None}
            events += self._step(m.name, present, state.yhat.get(m.name))
            watch = self.watch(m.name)
            if watch.excluded or any(f.statistic > self.suspect_gate for f in present.values()):
                withheld.add(m.name)
        excluded = frozenset(n for n, w in self.watches.items() if w.excluded)
        return Verdict(
            statistics,
            excluded,
            frozenset(withheld),
            tuple(ambiguous),
            tuple(events),
        )

    def _motion(self, support: SupportMeasurement, state: StationState) -> Innovation | None:
        """The fix against the support's motion reference (its last trusted fix, or where the
        formation placed it, carried by the moves commanded since)."""
        watch = self.watch(support.name)
        watch.motion_detectable_m = None
        if watch.reference is None or watch.reference_covariance is None:
            return None
        moved = _moved(support, state)
        watch.predicted = watch.reference + moved  # where the reference went, this cycle
        found = motion_innovation(
            support, watch.reference, moved, watch.reference_covariance, self.motion_sigma_m
        )
        if found is not None and self.fault_detectable > 0:  # its bias widens the radii
            watch.motion_detectable_m = detectable_bias(found.covariance, self.detectable)
        return found

    def _formation(
        self, measurements: Sequence[SupportMeasurement], suspect_motion: set[str]
    ) -> tuple[dict[str, Innovation], dict[str, Innovation], list[str]]:
        """Each contributing support's formation innovation against the trusted others (all of
        them, for the record), those that speak of the support itself (decisive), and the
        supports it cannot tell apart. A support not trusted is judged against the trusted;
        with three or more trusted, where several exceed, the largest is blamed if the others
        then agree; two trusted test only each other, a pair that cannot say which lies."""
        formation = self.formation = Formation(measurements, self.camera)  # settle reuses it
        contributing = list(formation.members)
        trusted = [
            name
            for name in contributing
            if not self.watch(name).excluded and name not in suspect_motion
        ]
        found = {name: formation.innovation(name, trusted) for name in contributing}
        found = {name: f for name, f in found.items() if f is not None}
        decisive = {name: f for name, f in found.items() if name not in trusted}
        over = [name for name in trusted if name in found and self._over(found[name])]
        if len(trusted) < 3:
            return found, decisive, over if len(over) > 1 else []
        if over:
            blamed = max(over, key=lambda name: found[name].statistic)
            rest = [name for name in trusted if name != blamed]
            again = {name: formation.innovation(name, rest) for name in rest}
            if any(f is not None and self._over(f) for f in again.values()):
                return found, decisive, over
            decisive[blamed] = found[blamed]
            decisive.update({name: f for name, f in again.items() if f is not None})
            return found, decisive, []
        decisive.update({name: found[name] for name in trusted if name in found})
        return found, decisive, []

    def _over(self, innovation: Innovation) -> bool:
        return innovation.statistic > self.gates[0]

    def _step(
        self, name: str, present: dict[str, Innovation], position: np.ndarray | None
    ) -> list[Event]:
        """The support's state machine, one cycle on (``position``: its last estimate)."""
        watch = self.watch(name)
        for test in TESTS:
            recent = watch.recent.setdefault(test, deque(maxlen=len(self.gates)))
            if test in present:
                recent.append(present[test].statistic)
            else:
                recent.clear()  # in a row, or not at all
        if not watch.excluded:
            test = self._exceeded(watch)
            if test is None:
                return []
            watch.excluded, watch.consistent, watch.travel_m = True, 0, 0.0
            watch.since, watch.receiver, watch.taught = None, False, []
            watch.biased_at = watch.quiet_at = position
            watch.biased_cycles = 1
            found = present[test]
            detectable_m = detectable_bias(found.covariance, self.detectable)
            return [Event(name, "excluded", test, found.size_m, detectable_m)]
        quiet = bool(present) and all(f.statistic <= self.suspect_gate for f in present.values())
        if not quiet:
            watch.consistent, watch.biased_at = 0, position
            watch.biased_cycles += 1
            return []
        watch.consistent += 1
        if watch.consistent == 1:
            watch.quiet_at = position  # where the bias was first gone
        if watch.consistent < self.settings.recovery_cycles:
            return []
        watch.excluded, watch.consistent = False, 0
        for recent in watch.recent.values():
            recent.clear()
        found = [Event(name, "restored")]
        if not watch.receiver and self._vanished_in_place(watch):
            watch.receiver = True
            found.insert(0, Event(name, "receiver"))
        return found

    def _vanished_in_place(self, watch: Watch) -> bool:
        """Whether a bias that lasted recovery_cycles went while the support stayed in the
        voxel where it was last seen: a place's bias stays with the place, a receiver's can
        end anywhere. (A shorter one, or one gone as the support moved, may have been a
        support dipping into a zone's face: that is kept as the place's.)"""
        if watch.biased_at is None or watch.quiet_at is None:
            return False
        if watch.biased_cycles < self.settings.recovery_cycles:
            return False
        moved = float(np.linalg.norm(np.asarray(watch.quiet_at) - watch.biased_at))
        return moved < self.voxel_m

    def _exceeded(self, watch: Watch) -> str | None:
        """The test whose statistics over the last m cycles exceed their gate (the largest
        excess first), or None."""
        worst, excess = None, 1.0
        for test, recent in watch.recent.items():
            values = list(recent)
            for m in range(1, len(values) + 1):
                ratio = sum(values[-m:]) / self.gates[m - 1]
                if ratio > excess:
                    worst, excess = test, ratio
        return worst

    def settle(
        self,
        measurements: Sequence[SupportMeasurement],
        state: StationState,
        fusion: FusionResult,
        verdict: Verdict,
    ) -> Verdict:
        """After the fusion: the withheld supports' navigation, each estimate's covariance and
        protection radius, the receiver calls (:func:`~.aftermath.settle`)."""
        return settle(self, measurements, state, fusion, verdict)

    def learn_excluded(
        self,
        g: LocalizabilityMap,
        measurements: Sequence[SupportMeasurement],
        yhat: dict[str, np.ndarray],
        events: Sequence[Event],
    ) -> int:
        """What the excluded supports teach G, and what a receiver's taught taken back
        (:func:`~.aftermath.learn_excluded`)."""
        return learn_excluded(self, g, measurements, yhat, events)

    def extra_margin_m(self, name: str, allowance_m: float) -> float:
        """How much further than the scenario's margins a support keeps from everything: its
        protection radius beyond ``allowance_m`` (the margins' own allowance for an
        estimate's error), and ``excluded_margin_m`` more while excluded."""
        watch = self.watches.get(name)
        if watch is None:
            return 0.0
        extra = max(0.0, (watch.protection_m or 0.0) - allowance_m)
        return extra + (self.settings.excluded_margin_m if watch.excluded else 0.0)


def fault_noncentrality(settings: IntegritySettings) -> float:
    """lambda* of an undetected fault in the protection radii: the bias a test misses with
    probability missed_detection / fault_prior; 0 where a fault is no likelier than the
    integrity risk (then it does not widen a radius)."""
    if settings.fault_prior <= settings.missed_detection:
        return 0.0
    allowed = min(0.5, settings.missed_detection / settings.fault_prior)
    return detectable_noncentrality(settings.false_alarm, allowed)


def _moved(support: SupportMeasurement, state: StationState) -> np.ndarray:
    """How far the support moved since the last cycle: as its autopilot reports it (its
    belief now, less the estimate it was sent then, which reset its belief), or, without that
    report, as it was commanded. A vehicle that did not fly its command (a setpoint its fence
    refused) moved as it reports, not as it was told."""
    sent = state.yhat.get(support.name)
    if support.belief_m is not None and sent is not None:
        return support.belief_m - sent
    return state.last_support_command.get(support.name, np.zeros(3))
