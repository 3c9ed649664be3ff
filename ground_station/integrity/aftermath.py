"""What the integrity monitor does after the fusion: the withheld supports' navigation (an
excluded one's: the formation's estimate less its sighting; else the fusion's dead reckoning), each
estimate's covariance and protection radius (:mod:`~.protection`), how far an excluded support
has carried its bias (past ``receiver_travel_m``: its receiver's), and what the excluded teach
G (taken back from a receiver)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np

from ground_station.estimation.fusion import FusionResult, SupportMeasurement
from ground_station.estimation.gnss_map import LocalizabilityMap
from ground_station.integrity.consistency import Formation
from ground_station.integrity.protection import detectable_bias, fault_shift
from ground_station.integrity.verdict import Event, Verdict, Watch
from ground_station.state.station_state import StationState
from mission.config.integrity_settings import IntegritySettings


class IntegrityMonitor(Protocol):
    """What this module reads of :class:`~.monitor.IntegrityMonitor`."""

    settings: IntegritySettings
    formation: Formation
    motion_sigma_m: float
    detectable: float
    fault_detectable: float
    k2: float

    def watch(self, name: str) -> Watch: ...


def settle(
    monitor: IntegrityMonitor,
    measurements: Sequence[SupportMeasurement],
    state: StationState,
    fusion: FusionResult,
    verdict: Verdict,
) -> Verdict:
    """The verdict with the cycle's receiver calls and every estimate's protection radius; the
    withheld supports' estimates (in ``state``) and every support's covariance set."""
    used = [name for name in fusion.consistent if name in monitor.formation.members]
    fused = None if fusion.xhat is None else monitor.formation.estimate(used)
    xhat_covariance = None if fused is None else fused[1]
    fault_x = 0.0 if xhat_covariance is None else _fault_term(monitor, used, xhat_covariance)
    covariances: dict[str, np.ndarray] = {}
    if xhat_covariance is not None:
        covariances["work"] = xhat_covariance
    events = []
    for m in measurements:
        watch = monitor.watch(m.name)
        _navigate(monitor, m, state, fusion, m.name in verdict.withheld, (xhat_covariance, fault_x))
        if watch.covariance is not None:
            covariances[m.name] = watch.covariance
        if watch.excluded and _followed(monitor, watch, state.yhat[m.name]):
            events.append(Event(m.name, "receiver"))
    radii = _no_fault_radii(covariances, monitor.k2)
    protection: dict[str, float | None] = {"work": None}
    if "work" in radii:
        protection["work"] = radii["work"] + fault_x
    for m in measurements:
        watch = monitor.watch(m.name)
        found = radii.get(m.name)
        watch.protection_m = None if found is None else found + watch.fault_m
        protection[m.name] = watch.protection_m
    return verdict.settled(events, protection)


def _no_fault_radii(covariances: dict[str, np.ndarray], k2: float) -> dict[str, float]:
    """sqrt(k2 lambda_max(P)) of every covariance, in one batch."""
    if not covariances:
        return {}
    largest = np.linalg.eigvalsh(np.array(list(covariances.values())))[:, -1]
    return {name: float(np.sqrt(k2 * max(value, 0.0))) for name, value in zip(covariances, largest)}


def _fault_term(monitor: IntegrityMonitor, used: list[str], covariance: np.ndarray) -> float:
    """The largest shift of xhat an undetected fault in one fused support could make (0 where
    a fault is no likelier than the integrity risk: :mod:`~.protection`)."""
    if monitor.fault_detectable == 0.0:
        return 0.0
    formation = monitor.formation
    lone = None
    if len(used) == 1 and monitor.watch(used[0]).motion_detectable_m is not None:
        own = monitor.watch(used[0]).motion_detectable_m
        lone = own * np.sqrt(monitor.fault_detectable / monitor.detectable)
    information = {name: formation.information[name] for name in used}
    sigma = {name: formation.sigma[name] for name in used}
    return fault_shift(covariance, information, sigma, monitor.fault_detectable, lone)


def _navigate(
    monitor: IntegrityMonitor,
    m: SupportMeasurement,
    state: StationState,
    fusion: FusionResult,
    withheld: bool,
    work: tuple[np.ndarray | None, float],
) -> None:
    """The support's estimate where the monitor decides it (excluded and seeing the work UAV:
    the formation's, ``work`` being xhat's covariance, None when blind, and its fault term; a
    support only withheld this cycle, suspect or ambiguous, stays dead-reckoned from its last
    trusted fix, as its sighting may be what is wrong), its covariance, and the undetected
    bias it may carry."""
    watch = monitor.watch(m.name)
    xhat_covariance, fault_x = work
    drift = monitor.motion_sigma_m**2 * np.eye(3)
    if withheld and watch.excluded and xhat_covariance is not None and m.relative_m is not None:
        assert fusion.xhat is not None and m.sigma_relative_m2 is not None
        state.yhat[m.name] = fusion.xhat - m.relative_m
        watch.covariance = xhat_covariance + m.sigma_relative_m2
        watch.fault_m = fault_x
        _refer(watch, state.yhat[m.name], watch.covariance)  # the formation's, not the fix
    elif not withheld and m.fix_m is not None and m.sigma_gnss_m2 is not None:
        watch.covariance = m.sigma_gnss_m2.copy()
        if m.relative_m is not None and m.sigma_relative_m2 is not None:
            watch.covariance += m.sigma_relative_m2  # yhat mixes the fix and x - r
        watch.fault_m = _own_fault(monitor, watch, m)
        tested = m.sigma_gnss_tested_m2
        assert tested is not None
        _refer(watch, m.fix_m, tested)  # a trusted fix: the next test's reference
    else:  # dead-reckoned by the fusion: it drifts, and so does the motion reference
        if watch.covariance is not None:
            watch.covariance = watch.covariance + drift
        if watch.predicted is not None and watch.reference_covariance is not None:
            _refer(watch, watch.predicted, watch.reference_covariance + drift)


def _refer(watch: Watch, position: np.ndarray, covariance: np.ndarray) -> None:
    """The motion test's next reference."""
    watch.reference = np.array(position, dtype=float)
    watch.reference_covariance = np.array(covariance, dtype=float)
    watch.predicted = None


def _own_fault(monitor: IntegrityMonitor, watch: Watch, m: SupportMeasurement) -> float:
    """The bias a support's own fix may carry into its estimate undetected."""
    if monitor.fault_detectable == 0.0:
        return 0.0  # a fault no likelier than the integrity risk
    own = watch.motion_detectable_m
    if own is not None:
        return own * np.sqrt(monitor.fault_detectable / monitor.detectable)
    assert m.sigma_gnss_m2 is not None
    return detectable_bias(2 * m.sigma_gnss_m2, monitor.fault_detectable)


def _followed(monitor: IntegrityMonitor, watch: Watch, yhat: np.ndarray) -> bool:
    """Whether the bias has now followed the excluded support past receiver_travel_m."""
    if watch.since is None:
        watch.since = np.array(yhat, dtype=float)
    watch.travel_m = max(watch.travel_m, float(np.linalg.norm(yhat - watch.since)))
    if watch.receiver or watch.travel_m <= monitor.settings.receiver_travel_m:
        return False
    watch.receiver = True
    return True


def learn_excluded(
    monitor: IntegrityMonitor,
    g: LocalizabilityMap,
    measurements: Sequence[SupportMeasurement],
    yhat: dict[str, np.ndarray],
    events: Sequence[Event],
) -> int:
    """G from the excluded supports that see the work UAV, recorded so that it can be taken
    back: an excluded support's bias is a place's (a zone) until it has followed the support
    past ``receiver_travel_m``, or gone while the support stayed in its voxel; then it was the
    receiver's and what it taught G is taken back (and it teaches nothing more until
    restored). Returns how many voxel updates were made."""
    for event in events:  # a receiver's teaching taken back, a place's kept once restored
        watch = monitor.watch(event.support)
        if event.kind == "receiver":
            g.take_back(watch.taught)
        if event.kind in ("receiver", "restored"):
            watch.taught = []
    updated = 0
    for m in measurements:
        watch = monitor.watch(m.name)
        if watch.excluded and not watch.receiver and m.contributes:
            assert m.fix_m is not None
            count, change = g.update_recorded(m.fix_m, yhat[m.name])
            updated += count
            if change is not None:
                watch.taught.append(change)
    return updated
