"""The canary: three short fixed runs a study makes at its start, whose decisions' digests
(:mod:`mission.analysis.decisions`) stand for what the code and machine decide.

A committed study's ``provenance.json`` keeps the canary its code gave. Today's code giving
another canary means the study's numbers may no longer be what the code gives: ``mission
study --verify`` says so first, and the suite fails until the study is made again or marked
historical (docs/development.md). Between them the runs exercise the defaults' whole cycle
(GNSS from the sky and the zones, the fusion, G, the MPCs with their margins) with kinematic
points in Along; a flying quadrotor in gusty wind with dynamic roles, routes and the work
UAV's own fix in piers; and the integrity monitor excluding and restoring a glitched support
in Along; and dynamic roles again with kinematic points in piers: 40 simulated seconds each,
about 3, 6, 3 and 5 s of wall time. A study made before a run joined the canary is compared on
the runs both have; a canary run that flies quadrotors speaks only for studies that fly them
(:func:`flies_quadrotors`): a study of kinematic points is not made stale by a change to the
quadrotors' model.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from typing import Any

from mission.studies.runkeys import StudyRun, keyed_run, resolved_key
from mission.studies.spec import Point, StudySpec, validate_points

CANARY_S = 40.0  # simulated seconds of each canary run


@dataclass(frozen=True)
class CanaryRun:
    """One run of the canary."""

    scenario: str  # an embedded scenario
    overrides: tuple[tuple[str, Any], ...]
    method: str
    seed: int

    @property
    def label(self) -> str:
        """``along AC seed 0 (run.timeout_s=40.0)``."""
        point = Point(self.overrides).label
        return f"{self.scenario} {self.method.upper()} seed {self.seed} ({point})"


CANARY = (
    CanaryRun("along", (("run.timeout_s", CANARY_S),), "ac", 0),
    CanaryRun(
        "piers",
        (
            ("run.timeout_s", CANARY_S),
            ("roles.policy", "dynamic"),
            ("vehicle.dynamics", "multicopter"),
            ("world.wind.speed_m_s", 3.0),
        ),
        "ac",
        0,
    ),
    CanaryRun(
        "along",
        (
            ("run.timeout_s", CANARY_S),
            ("integrity.enabled", True),
            (
                "faults",
                [
                    {
                        "at_s": 10,
                        "vehicle": "support-1",
                        "param": "SIM_GPS1_GLTCH_X",
                        "value": 0.00002,
                        "duration_s": 15,
                    }
                ],
            ),
        ),
        "ac",
        0,
    ),
    # dynamic roles, routes and the work UAV's own fix with kinematic points: what the flying
    # run above covers for studies of quadrotors, for studies without them
    CanaryRun("piers", (("run.timeout_s", CANARY_S), ("roles.policy", "dynamic")), "ac", 0),
)


def canary_runs(code: str) -> list[StudyRun]:
    """The canary's runs, keyed as a study's runs are (named ``canary-<scenario>-<n>``, so a
    shared runs folder holds them once per code version)."""
    runs = []
    for number, canary in enumerate(CANARY):
        point = Point(canary.overrides)
        where = (canary.scenario, f"canary-{canary.scenario}-{number}", number, point)
        resolved = resolved_key(canary.scenario, point)
        runs.append(keyed_run(where, resolved, canary.method, canary.seed, code))
    return runs


def canary_record(summaries: list[dict[str, Any] | None]) -> dict[str, Any]:
    """What provenance.json keeps of the canary: each run's label and digest, and one digest
    of them all (None where a run failed or gave none)."""
    digests = [(summary or {}).get("decisions_digest") for summary in summaries]
    combined = None
    if digests and all(digests):
        text = json.dumps(digests).encode()
        combined = hashlib.sha256(text).hexdigest()[:16]
    return {
        "digest": combined,
        "runs": [
            {"run": canary.label, "decisions_digest": digest}
            for canary, digest in zip(CANARY, digests)
        ],
    }


QUADROTORS = ("vehicle.dynamics", "multicopter")


def flies_quadrotors(spec: StudySpec) -> bool:
    """Whether any of the study's runs flies quadrotors (``vehicle.dynamics: multicopter``)."""
    return any(s.vehicle.dynamics == "multicopter" for s in validate_points(spec).values())


def canary_differences(
    theirs: dict[str, Any] | None, today: dict[str, Any], quadrotors: bool = True
) -> list[str] | None:
    """The canary runs whose digests differ between a study's canary and today's, over the
    runs both name (None where they share none, or either has no digest for one);
    ``quadrotors`` False: a study that flies none, for which the runs that fly them do not
    speak."""
    mine = {r["run"]: r.get("decisions_digest") for r in today.get("runs", [])}
    old = {r["run"]: r.get("decisions_digest") for r in (theirs or {}).get("runs", [])}
    flying = {c.label for c in CANARY if QUADROTORS in c.overrides}
    shared = [run for run in old if run in mine and (quadrotors or run not in flying)]
    if not shared or any(old[run] is None or mine[run] is None for run in shared):
        return None
    return [run for run in shared if old[run] != mine[run]]
