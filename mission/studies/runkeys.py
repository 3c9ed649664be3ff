"""What identifies a study's run, so a rerun skips what is done: the resolved scenario (every
setting, and the contents of the files it names), the method, the seed and the code version.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

from mission.config.scenario import resolved_mapping, scenario_layers
from mission.link.plan_files import vehicle_names
from mission.studies.spec import Point, StudySpec

# The code a run executes and whose change can change its summary: the vehicles, the ground
# station, and the parts of `mission` they and the summary use. Not the study driver, the
# command line, the planner or the figures.
_RUN_CODE = (
    "vehicle_sim",
    "ground_station",
    "mission/config",
    "mission/world",
    "mission/link",
    "mission/procs",
    "mission/analysis",
    "mission/scenarios",
    "mission/codegen",
    "mission/runs/orchestrator.py",
)


@dataclass(frozen=True, eq=False)
class StudyRun:
    """One run of a study (compared and hashed by identity)."""

    scenario: str  # the base scenario's reference (embedded name or absolute path)
    scenario_name: str
    point: int  # index into the study's points
    overrides: dict[str, Any]
    method: str
    seed: int
    key: str  # hex digest of what determines the run's results
    speedup: float | None = None  # real time at this speed-up; None: lockstep

    @property
    def folder(self) -> str:
        """Its folder under ``runs/``: readable, and unique by the key."""
        return f"{self.scenario_name}-{self.method}-{self.seed}-{self.key[:10]}"


def code_version() -> str:
    """A digest of the source and data files a run executes (see ``_RUN_CODE``)."""
    digest = hashlib.sha256()
    for entry in _RUN_CODE:
        package, _, inner = entry.partition("/")
        root = Path(str(resources.files(package)))
        place = root / inner if inner else root
        files = sorted(place.rglob("*")) if place.is_dir() else [place]
        for path in files:
            if path.is_file() and path.suffix in (".py", ".yaml", ".waypoints", ".csv"):
                digest.update(str(path.relative_to(root.parent)).encode())
                digest.update(path.read_bytes())
    return digest.hexdigest()


def study_runs(spec: StudySpec, names: dict[str, str], code: str) -> list[StudyRun]:
    """Every run of the study in order (scenario, point, seed, method: pairs side by side);
    ``names`` gives each scenario reference's own name."""
    runs = []
    digests: dict[Path, str] = {}  # each named file read once for every point
    for scenario in spec.scenarios:
        layers = scenario_layers(scenario)
        for number, point in enumerate(spec.points):
            resolved = resolved_key(scenario, point, layers, digests)
            for seed in spec.seeds:
                for method in spec.methods:
                    where = (scenario, names[scenario], number, point)
                    runs.append(keyed_run(where, resolved, method, seed, code, spec.speedup))
    return runs


def keyed_run(
    where: tuple[str, str, int, Point],
    resolved: str,
    method: str,
    seed: int,
    code: str,
    speedup: float | None = None,
) -> StudyRun:
    """A run of ``where`` (scenario reference, its name, point number, point), whose
    resolved scenario has the digest ``resolved``, keyed by all that determines it."""
    scenario, name, number, point = where
    identity = {"scenario": resolved, "method": method, "seed": seed, "code": code}
    if speedup is not None:  # a lockstep run's key names no clock
        identity["realtime"] = speedup
    key = _digest(identity)
    return StudyRun(scenario, name, number, point.as_dict(), method, seed, key, speedup)


def resolved_key(
    scenario: str,
    point: Point,
    layers: dict[str, Any] | None = None,
    digests: dict[Path, str] | None = None,
) -> str:
    """A digest of the resolved scenario: its settings with the contents (not the paths) of
    the files they name (``layers``: the scenario's files read already; ``digests``: the
    files' digests found so far, added to)."""
    mapping = resolved_mapping(scenario, point.as_dict(), layers)
    files = _named_files(mapping, {} if digests is None else digests)
    for key in ("mesh_file", "waypoints_dir", "table"):
        _drop_path(mapping, key)
    return _digest({"settings": mapping, "files": files})


def _named_files(mapping: dict[str, Any], digests: dict[Path, str]) -> dict[str, str]:
    """Digest of each file the settings name: the mesh, the sky table, the waypoint files
    (each read once: ``digests`` keeps them)."""
    files = {}
    mesh = mapping.get("world", {}).get("structure", {}).get("mesh_file")
    if mesh:
        files["mesh"] = _file_digest(Path(mesh), digests)
    table = mapping.get("sky", {}).get("table")
    if table and table != "builtin":
        files["sky"] = _file_digest(Path(table), digests)
    task = mapping.get("task", {})
    folder = Path(task.get("waypoints_dir", "."))
    supports = task.get("supports", 0)
    if isinstance(supports, int) and supports > 0:
        for name in vehicle_names(supports):
            files[name] = _file_digest(folder / f"{name}.waypoints", digests)
    return files


def _file_digest(path: Path, digests: dict[Path, str]) -> str:
    if path not in digests:
        try:
            digests[path] = hashlib.sha256(path.read_bytes()).hexdigest()
        except OSError:
            digests[path] = "missing"
    return digests[path]


def _drop_path(mapping: dict[str, Any], key: str) -> None:
    for value in mapping.values():
        if isinstance(value, dict):
            value.pop(key, None)
            _drop_path(value, key)


def _digest(value: Any) -> str:
    return hashlib.sha256(json.dumps(value, sort_keys=True, default=str).encode()).hexdigest()
