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
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from ground_station.fusion import FusionResult, SupportMeasurement
from ground_station.gnss_map import Change, LocalizabilityMap
from ground_station.integrity.chi_square import detectable_noncentrality, gate
from ground_station.integrity.consistency import (
    Innovation,
    formation_innovation,
    motion_innovation,
)
from ground_station.integrity.protection import (
    detectable_bias,
    fused_protection,
    no_fault_radius,
)
from ground_station.state import StationState
from mission.config.integrity_settings import IntegritySettings

SUSPECT_EXPONENT = 0.5  # the suspect gate's false-alarm rate is false_alarm ** this
TESTS = ("motion", "formation")


@dataclass
class Watch:
    """What the monitor carries for one support between cycles."""

    covariance: np.ndarray | None = None  # of its estimate, for the motion test
    excluded: bool = False
    recent: dict[str, deque[float]] = field(default_factory=dict)  # each test's statistics
    consistent: int = 0  # cycles in a row under the suspect gate, while excluded
    since: np.ndarray | None = None  # its estimate where it was excluded
    travel_m: float = 0.0  # how far its estimate went from there while excluded
    receiver: bool = False  # the bias followed it: its receiver's, not a place's
    taught: list[Change] = field(default_factory=list)  # what it taught G while excluded
    motion_detectable_m: float | None = None  # its motion test's MDB this cycle
    fault_m: float = 0.0  # the undetected bias its estimate may carry (protection radius)
    protection_m: float | None = None  # its estimate's protection radius


@dataclass(frozen=True)
class Event:
    """An exclusion, a restoration, or a bias found to follow a support (its receiver's)."""

    support: str
    kind: str  # excluded, restored, receiver
    test: str = ""
    size_m: float = 0.0  # |nu| of the test that excluded it
    detectable_m: float = 0.0  # that test's minimal detectable bias (its worst direction)

    def record(self) -> dict:
        """What records.jsonl keeps of it."""
        found = {"support": self.support, "kind": self.kind}
        if self.kind == "excluded":
            found.update(
                test=self.test, size_m=round(self.size_m, 3), mdb_m=round(self.detectable_m, 3)
            )
        return found

    @property
    def text(self) -> str:
        """The STATUSTEXT the ground station sends."""
        if self.kind == "excluded":
            return f"Integrity: {self.support} excluded ({self.test} test, {self.size_m:.1f} m)"
        if self.kind == "receiver":
            return f"Integrity: {self.support} receiver at fault"
        return f"Integrity: {self.support} restored"


@dataclass(frozen=True)
class Verdict:
    """One cycle's outcome: each support's statistics, who is excluded, who is withheld from
    the fusion this cycle (the excluded, the suspect, the ambiguous), and what changed."""

    statistics: dict[str, dict[str, float]]
    excluded: frozenset[str]
    withheld: frozenset[str]
    ambiguous: tuple[str, ...]
    events: tuple[Event, ...]
    protection_m: dict[str, float | None] = field(default_factory=dict)  # work and supports

    def settled(self, found: Sequence[Event], protection: dict[str, float | None]) -> Verdict:
        """The verdict with what the cycle found after the fusion, and the estimates'
        protection radii."""
        return replace(self, events=self.events + tuple(found), protection_m=protection)

    def record(self) -> dict:
        """What records.jsonl keeps of it."""
        return {
            "statistics": {
                name: {test: round(value, 3) for test, value in tests.items()}
                for name, tests in self.statistics.items()
            },
            "excluded": sorted(self.excluded),
            "withheld": sorted(self.withheld),
            "ambiguous": list(self.ambiguous),
            "events": [event.record() for event in self.events],
            "protection_m": {
                name: None if radius is None else round(radius, 3)
                for name, radius in self.protection_m.items()
            },
        }


class IntegrityMonitor:
    """Tests every support's fix each cycle (:meth:`check`) and keeps each one's covariance
    and state (:meth:`settle`, after the fusion)."""

    def __init__(self, settings: IntegritySettings, multicopter: bool) -> None:
        self.settings = settings
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
        formation, ambiguous = self._formation(measurements, suspect_motion)
        statistics: dict[str, dict[str, float]] = {}
        events: list[Event] = []
        withheld = set(ambiguous)
        for m in measurements:
            found = {"motion": motion[m.name], "formation": formation.get(m.name)}
            present = {test: f for test, f in found.items() if f is not None}
            statistics[m.name] = {test: f.statistic for test, f in present.items()}
            event = self._step(m.name, present)
            if event is not None:
                events.append(event)
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
        watch = self.watch(support.name)
        watch.motion_detectable_m = None
        previous = state.yhat.get(support.name)
        if watch.covariance is None or previous is None:
            return None
        moved = state.last_support_command.get(support.name, np.zeros(3))
        found = motion_innovation(support, previous, moved, watch.covariance, self.motion_sigma_m)
        if found is not None:
            watch.motion_detectable_m = detectable_bias(found.covariance, self.detectable)
        return found

    def _formation(
        self, measurements: Sequence[SupportMeasurement], suspect_motion: set[str]
    ) -> tuple[dict[str, Innovation], list[str]]:
        """Each contributing support's formation innovation against the trusted others, with
        the liar identified where the others exceed too; and the supports it cannot tell
        apart."""
        contributing = [m for m in measurements if m.contributes]
        trusted = [
            m
            for m in contributing
            if not self.watch(m.name).excluded and m.name not in suspect_motion
        ]
        found = {m.name: formation_innovation(m, trusted) for m in contributing}
        found = {name: f for name, f in found.items() if f is not None}
        over = [m.name for m in trusted if m.name in found and self._over(found[m.name])]
        if not over:
            return found, []
        if len(trusted) >= 3:
            blamed = max(over, key=lambda name: found[name].statistic)
            rest = [m for m in trusted if m.name != blamed]
            again = {m.name: formation_innovation(m, rest) for m in rest}
            if not any(f is not None and self._over(f) for f in again.values()):
                found.update({name: f for name, f in again.items() if f is not None})
                return found, []
        return {n: f for n, f in found.items() if n not in over}, over

    def _over(self, innovation: Innovation) -> bool:
        return innovation.statistic > self.gates[0]

    def _step(self, name: str, present: dict[str, Innovation]) -> Event | None:
        """The support's state machine, one cycle on."""
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
                return None
            watch.excluded, watch.consistent, watch.travel_m = True, 0, 0.0
            watch.since, watch.receiver, watch.taught = None, False, []
            found = present[test]
            detectable_m = detectable_bias(found.covariance, self.detectable)
            return Event(name, "excluded", test, found.size_m, detectable_m)
        quiet = bool(present) and all(f.statistic <= self.suspect_gate for f in present.values())
        watch.consistent = watch.consistent + 1 if quiet else 0
        if watch.consistent < self.settings.recovery_cycles:
            return None
        watch.excluded, watch.consistent, watch.taught = False, 0, []  # what it taught stays
        for recent in watch.recent.values():
            recent.clear()
        return Event(name, "restored")

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
        """After the fusion (which had no fix of the withheld supports, so dead-reckoned
        them): a withheld support that sees the work UAV is placed by the formation instead
        (xhat - r_n); each estimate's covariance and protection radius; how far an excluded
        support has gone, and, past ``receiver_travel_m``, its bias called its receiver's.
        Returns the verdict with those findings and radii."""
        used = [m for m in measurements if m.name in fusion.consistent and m.contributes]
        scale = np.sqrt(self.fault_detectable / self.detectable)  # MDB at the fault's rate
        motion_mdb = {m.name: self.watch(m.name).motion_detectable_m for m in used}
        detected = {name: mdb * scale for name, mdb in motion_mdb.items() if mdb is not None}
        work = (
            None
            if fusion.xhat is None
            else fused_protection(used, self.fault_detectable, self.k2, detected)
        )
        protection: dict[str, float | None] = {"work": None if work is None else work[0]}
        xhat_covariance = _fused_covariance(measurements, fusion)
        fault_x = 0.0 if work is None else work[1]
        events = []
        for m in measurements:
            watch = self.watch(m.name)
            self._navigate(m, state, fusion, m.name in verdict.withheld, (xhat_covariance, fault_x))
            protection[m.name] = watch.protection_m = (
                None
                if watch.covariance is None
                else no_fault_radius(watch.covariance, self.k2) + watch.fault_m
            )
            if watch.excluded and self._followed(watch, state.yhat[m.name]):
                events.append(Event(m.name, "receiver"))
        return verdict.settled(events, protection)

    def _navigate(
        self,
        m: SupportMeasurement,
        state: StationState,
        fusion: FusionResult,
        withheld: bool,
        work: tuple[np.ndarray | None, float],
    ) -> None:
        """The support's estimate where the monitor decides it (withheld and seeing the work
        UAV: the formation's, ``work`` being xhat's covariance, None when blind, and its fault
        term), its covariance, and the undetected bias it may carry."""
        watch = self.watch(m.name)
        xhat_covariance, fault_x = work
        if withheld and xhat_covariance is not None and m.relative_m is not None:
            assert fusion.xhat is not None and m.sigma_relative_m2 is not None
            state.yhat[m.name] = fusion.xhat - m.relative_m
            watch.covariance = xhat_covariance + m.sigma_relative_m2
            watch.fault_m = fault_x
        elif not withheld and m.fix_m is not None and m.sigma_gnss_m2 is not None:
            watch.covariance = m.sigma_gnss_m2.copy()
            if m.relative_m is not None and m.sigma_relative_m2 is not None:
                watch.covariance += m.sigma_relative_m2  # yhat mixes the fix and x - r
            own = watch.motion_detectable_m
            if self.fault_detectable == 0.0:
                watch.fault_m = 0.0  # a fault no likelier than the integrity risk
            elif own is not None:
                watch.fault_m = own * np.sqrt(self.fault_detectable / self.detectable)
            else:
                watch.fault_m = detectable_bias(2 * m.sigma_gnss_m2, self.fault_detectable)
        elif watch.covariance is not None:  # dead-reckoned by the fusion: it drifts
            watch.covariance = watch.covariance + self.motion_sigma_m**2 * np.eye(3)

    def _followed(self, watch: Watch, yhat: np.ndarray) -> bool:
        """Whether the bias has now followed the excluded support past receiver_travel_m."""
        if watch.since is None:
            watch.since = np.array(yhat, dtype=float)
        watch.travel_m = max(watch.travel_m, float(np.linalg.norm(yhat - watch.since)))
        if watch.receiver or watch.travel_m <= self.settings.receiver_travel_m:
            return False
        watch.receiver = True
        return True

    def learn_excluded(
        self,
        g: LocalizabilityMap,
        measurements: Sequence[SupportMeasurement],
        yhat: dict[str, np.ndarray],
        events: Sequence[Event],
    ) -> int:
        """G from the excluded supports that see the work UAV, recorded so that it can be
        taken back: an excluded support's bias is a place's (a zone) until it has followed the
        support, then it is the receiver's and what it taught G is taken back (and it teaches
        nothing more until restored). Returns how many voxel updates were made."""
        for event in events:
            watch = self.watch(event.support)
            if event.kind == "receiver":
                g.take_back(watch.taught)
                watch.taught = []
        updated = 0
        for m in measurements:
            watch = self.watch(m.name)
            if watch.excluded and not watch.receiver and m.contributes:
                assert m.fix_m is not None
                count, change = g.update_recorded(m.fix_m, yhat[m.name])
                updated += count
                if change is not None:
                    watch.taught.append(change)
        return updated

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


def _fused_covariance(
    measurements: Sequence[SupportMeasurement], fusion: FusionResult
) -> np.ndarray | None:
    """xhat's covariance from the supports in S (information-summed), or None when blind."""
    if fusion.xhat is None:
        return None
    used = [m for m in measurements if m.name in fusion.consistent and m.contributes]
    if not used:
        return None
    information = sum(np.linalg.inv(m.sigma) for m in used)
    return np.linalg.inv(information)
