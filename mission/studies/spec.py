"""A study file: which scenarios, methods, seeds and points (sets of overrides) to run.

```yaml
name: fusion-leakage          # names the output folder (default: the file's stem)
description: ...
scenarios: [along, wall]      # embedded names or paths (relative to this file)
methods: [ac, nac]            # default: both
seeds: 15                     # 0..14; or a list [0, 3, 7]; or {start: 100, count: 15}
grid:                         # every combination of these (dotted scenario keys)
  fusion.rho_threshold: [0.0, 0.25, 0.5]
  fusion.broad_sigma_m: [0.5, 1.0, 2.0]
points:                       # and/or a list of override sets, each crossed with the grid
  - {}
  - {fusion.agreement: paper}
tables: [table3]              # also write the paper's Table 3 (table.md, table.csv, boxplots)
realtime: 10                  # run in real time at this speed-up (default: lockstep)
```

Every (scenario, point) is resolved and validated before anything runs: a bad key or value
is one line naming this file, the point and the key.
"""

from __future__ import annotations

import itertools
import json
import math
from collections.abc import Callable
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

from mission.config.errors import InputError, ScenarioError
from mission.config.scenario import (
    load_scenario,
    read_yaml_mapping,
    resolve_scenario_path,
    scenario_layers,
)
from mission.config.settings import Scenario
from mission.procs.command_line import MAX_SPEEDUP, MIN_SPEEDUP

METHODS = ("ac", "nac")
TABLES = ("table3",)
_KEYS = {
    "name",
    "description",
    "scenarios",
    "methods",
    "seeds",
    "grid",
    "points",
    "tables",
    "realtime",
}
MAX_RUNS = 1_000_000
# A point's scenario is resolved and checked in a few milliseconds: this many take well under
# a minute, and a study of more than ANNOUNCED_POINTS says so before it checks them.
MAX_POINTS = 10_000
ANNOUNCED_POINTS = 200
ANNOUNCED_RUNS = 10_000  # planning a run's key takes ~20 us: 10^6 take ~20 s
ANNOUNCED_BYTES = 1_000_000  # a study file this long takes seconds to read


@dataclass(frozen=True, eq=False)
class Point:
    """One set of overrides: ((dotted key, value), ...) in the study file's order."""

    overrides: tuple[tuple[str, Any], ...]

    def as_dict(self) -> dict[str, Any]:
        """{dotted key: value}."""
        return dict(self.overrides)

    @property
    def label(self) -> str:
        """``key=value, ...`` (``defaults`` for none; ``faults`` told briefly)."""
        return ", ".join(f"{k}={value_text(k, v)}" for k, v in self.overrides) or "defaults"


def value_text(key: str, value: Any) -> str:
    """A point's value as its label shows it: a scenario's ``faults:`` entries as
    ``support-1 gps off 10-40 s``; a run of more than three settings of one vehicle's one
    parameter back to back as a ramp (``support-1 SIM_GPS1_GLTCH_Z 0.1 to 3 in 30 steps,
    10-40 s``); anything else as Python prints it."""
    if key != "faults" or not isinstance(value, list):
        return str(value)
    if not all(isinstance(fault, dict) for fault in value):
        return str(value)
    ramp = _ramp_text(value)
    if ramp is not None:
        return ramp
    told = []
    for fault in value:
        what = fault.get("failure") or f"{fault.get('param')}={fault.get('value')}"
        start, duration = fault.get("at_s"), fault.get("duration_s")
        when = f"from {start} s" if duration is None else f"{start}-{start + duration:g} s"
        told.append(f"{fault.get('vehicle')} {what} {when}")
    return "; ".join(told) or "none"


def _ramp_text(faults: list[dict[str, Any]]) -> str | None:
    """More than three settings of one vehicle's one parameter, each starting as the last
    ends, told as a ramp (None where the faults are not that)."""
    if len(faults) <= 3:
        return None
    firsts = faults[0]
    same = all(
        f.get("vehicle") == firsts.get("vehicle") and f.get("param") == firsts.get("param")
        for f in faults
    )
    if not same or firsts.get("param") is None:
        return None
    try:
        ends = [float(f["at_s"]) + float(f["duration_s"]) for f in faults]
        if any(abs(float(f["at_s"]) - end) > 1e-9 for f, end in zip(faults[1:], ends)):
            return None
    except (KeyError, TypeError, ValueError):
        return None
    return (
        f"{firsts['vehicle']} {firsts['param']} {firsts.get('value')} to "
        f"{faults[-1].get('value')} in {len(faults)} steps, {firsts['at_s']}-{ends[-1]:g} s"
    )


@dataclass(frozen=True)
class StudySpec:
    """A validated study."""

    name: str
    description: str
    source: Path
    scenarios: tuple[str, ...]  # as resolvable references (embedded name or absolute path)
    methods: tuple[str, ...]
    seeds: tuple[int, ...]
    points: tuple[Point, ...]
    tables: tuple[str, ...]
    speedup: float | None = None  # real time at this speed-up; None: lockstep

    @property
    def swept_keys(self) -> list[str]:
        """The dotted keys some point sets, in order of first appearance."""
        keys: dict[str, None] = {}
        for point in self.points:
            keys.update((k, None) for k, _ in point.overrides)
        return list(keys)

    @property
    def size(self) -> int:
        """How many runs the study has."""
        return len(self.scenarios) * len(self.points) * len(self.methods) * len(self.seeds)


def _speedup(source: str, value: Any) -> float | None:
    """``realtime``: a speed-up in [MIN_SPEEDUP, MAX_SPEEDUP], or absent (lockstep)."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(source, "realtime", f"must be a speed-up (a number), got {value!r}")
    if not MIN_SPEEDUP <= value <= MAX_SPEEDUP:
        span = f"[{MIN_SPEEDUP:g}, {MAX_SPEEDUP:g}]"
        raise InputError(source, "realtime", f"must be in {span}, got {value:g}")
    return float(value)


def load_study(path: Path, say: Callable[[str], None] | None = None) -> StudySpec:
    """Read and validate a study file (every scenario at every point included); ``say`` is
    told, before a long check of the points starts, how many there are."""
    path = shipped_study(path) or path
    source = str(path)
    size = path.stat().st_size if path.is_file() else 0
    if say is not None and size > ANNOUNCED_BYTES:
        say(f"reading {source} ({size / 1e6:.1f} MB)")
    data = read_yaml_mapping(path) if path.is_file() else _missing(path)
    return study_from_mapping(data, path, say)


def study_from_mapping(
    data: dict[str, Any], path: Path, say: Callable[[str], None] | None = None
) -> StudySpec:
    """Validate a study given as the mapping its file would hold; ``path``: the file it
    stands for (its name's default, and what relative scenario paths are relative to)."""
    source = str(path)
    unknown = sorted(set(map(str, data)) - _KEYS)
    if unknown:
        raise InputError(source, unknown[0], f"unknown key (expected one of: {_known()})")
    name = data.get("name", path.stem)
    if not isinstance(name, str) or not name or "/" in name or name.startswith("."):
        raise InputError(source, "name", "must be a plain folder name")
    listed = data.get("scenarios")
    if not isinstance(listed, list) or not listed:
        raise InputError(source, "scenarios", "must be a non-empty list of names or paths")
    scenarios = tuple(_listed_scenario(path, reference, i) for i, reference in enumerate(listed))
    methods_given = data.get("methods", list(METHODS))
    if not isinstance(methods_given, list) or not methods_given:
        raise InputError(source, "methods", "must be a non-empty list (ac, nac)")
    methods = tuple(str(m).lower() for m in methods_given)
    for method in methods:
        if method not in METHODS:
            raise InputError(source, "methods", f"{method!r} is not one of ac, nac")
    tables_given = data.get("tables", [])
    if not isinstance(tables_given, list):
        raise InputError(source, "tables", f"must be a list (of {', '.join(TABLES)})")
    tables = tuple(tables_given)
    for table in tables:
        if table not in TABLES:
            raise InputError(source, "tables", f"{table!r} is not one of {', '.join(TABLES)}")
    spec = StudySpec(
        name=name,
        description=str(data.get("description", "")).strip(),
        source=path.resolve(),
        scenarios=scenarios,
        methods=tuple(dict.fromkeys(methods)),
        seeds=_seeds(source, data.get("seeds", 1)),
        points=_points(source, data.get("grid"), data.get("points")),
        tables=tables,
        speedup=_speedup(source, data.get("realtime")),
    )
    if tables and len(spec.points) > 1:
        raise InputError(source, "tables", "Table 3 is for a study of one point (no grid)")
    if spec.size > MAX_RUNS:
        raise InputError(source, "", f"{spec.size} runs; at most {MAX_RUNS} in one study")
    if say is not None and spec.size > ANNOUNCED_RUNS:
        say(f"{spec.size:,} runs: checking and planning them takes a while")
    checked = len(spec.points) * len(spec.scenarios)
    if say is not None and checked > ANNOUNCED_POINTS:
        say(f"checking the scenario of each of {checked:,} points (a few ms each)")
    validate_points(spec)
    return spec


def validate_points(spec: StudySpec) -> dict[tuple[str, int], Scenario]:
    """Every (scenario, point number) resolved as a scenario; the first bad one raises, naming
    the study file, the point and the key (the scenario's file where the point changes
    nothing)."""
    resolved = {}
    for scenario in spec.scenarios:
        layers = scenario_layers(scenario)  # its files read once for every point
        for number, point in enumerate(spec.points):
            try:
                resolved[(scenario, number)] = load_scenario(scenario, point.as_dict(), layers)
            except ScenarioError as error:
                if not point.overrides:  # the scenario's own file is at fault: it is named
                    raise
                where = f"point {number} ({point.label}): {error.where}".rstrip(": ")
                raise InputError(str(spec.source), where, error.problem) from None
            except ValueError as error:
                raise InputError(str(spec.source), f"point {number}", str(error)) from None
    return resolved


def shipped_studies_dir() -> Path:
    """Where the studies shipped inside the package are (docs/studies holds their results)."""
    return Path(str(resources.files("mission.studies") / "shipped"))


def shipped_study_names() -> list[str]:
    """The names of the shipped studies, as ``mission study NAME`` takes them."""
    return sorted(p.stem for p in shipped_studies_dir().glob("*.yaml"))


def shipped_study(reference: Path) -> Path | None:
    """The shipped study a bare name (no folder, no suffix, not a file here) stands for."""
    if reference.is_file() or reference.suffix or len(reference.parts) != 1:
        return None
    candidate = shipped_studies_dir() / f"{reference.name}.yaml"
    return candidate if candidate.is_file() else None


def _missing(path: Path) -> dict[str, Any]:
    shipped = ", ".join(shipped_study_names())
    raise InputError(str(path), "", f"no such study file or shipped study (shipped: {shipped})")


def _known() -> str:
    return ", ".join(sorted(_KEYS))


def _listed_scenario(study: Path, reference: Any, index: int) -> str:
    if not isinstance(reference, str) or not reference:
        raise InputError(str(study), f"scenarios[{index}]", "must be a name or a path")
    return scenario_reference(study.parent, reference, f"scenarios[{index}]", str(study))


def scenario_reference(
    folder: Path, reference: str, where: str, source: str = "command line"
) -> str:
    """An embedded name as it is; a path made absolute against ``folder``; one that names
    no scenario raises naming ``source`` and ``where``."""
    candidate = Path(reference)
    if candidate.suffix in (".yaml", ".yml") and not candidate.is_absolute():
        reference = str((folder / candidate).resolve())
    try:
        resolve_scenario_path(reference)
    except ScenarioError as error:
        raise InputError(source, where, error.problem) from None
    return reference


def _seeds(source: str, value: Any) -> tuple[int, ...]:
    if isinstance(value, bool):
        raise InputError(source, "seeds", "must be a count, a list or {start, count}")
    count = value if isinstance(value, int) else None
    if isinstance(value, dict) and isinstance(value.get("count"), int):
        count = value["count"]
    if count is not None and count > MAX_RUNS:  # before a list of them is made
        raise InputError(source, "seeds", f"{count} seeds; at most {MAX_RUNS} runs in one study")
    if isinstance(value, int):
        seeds = list(range(value))
    elif isinstance(value, list):
        seeds = value
    elif isinstance(value, dict) and set(value) == {"start", "count"}:
        start, count = value["start"], value["count"]
        if not all(isinstance(v, int) and not isinstance(v, bool) for v in (start, count)):
            raise InputError(source, "seeds", "start and count must be integers")
        seeds = list(range(start, start + count))
    else:
        raise InputError(source, "seeds", "must be a count, a list or {start, count}")
    if not seeds:
        raise InputError(source, "seeds", "names no seed")
    for seed in seeds:
        if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**32:
            raise InputError(source, "seeds", f"{seed!r} is not a seed in 0..2^32-1")
    if len(set(seeds)) != len(seeds):
        raise InputError(source, "seeds", "a seed appears twice")
    return tuple(seeds)


def _points(source: str, grid: Any, points: Any) -> tuple[Point, ...]:
    """The points: each of ``points`` (default: one with no override) crossed with the grid."""
    if grid is None:
        grid = {}
    if not isinstance(grid, dict):
        raise InputError(source, "grid", "must map dotted keys to lists of values")
    for key, values in grid.items():
        if not isinstance(values, list) or not values:
            raise InputError(source, f"grid.{key}", "must be a non-empty list of values")
    if points is None:
        points = [{}]
    if not isinstance(points, list) or not points:
        raise InputError(source, "points", "must be a non-empty list of override mappings")
    for number, point in enumerate(points):
        if not isinstance(point, dict):
            raise InputError(source, f"points[{number}]", "must map dotted keys to values")
        clash = sorted(set(map(str, point)) & set(map(str, grid)))
        if clash:
            raise InputError(source, f"points[{number}].{clash[0]}", "is also a grid key")
    size = len(points) * math.prod(len(values) for values in grid.values())
    if size > MAX_POINTS:  # before the grid is expanded
        raise InputError(source, "grid", f"{size:,} points; at most {MAX_POINTS:,} in one study")
    combos = list(itertools.product(*grid.values()))
    expanded = [
        Point(tuple((str(k), v) for k, v in point.items()) + tuple(zip(map(str, grid), combo)))
        for point in points
        for combo in combos
    ]
    if len({json.dumps(p.overrides, sort_keys=True) for p in expanded}) != len(expanded):
        raise InputError(source, "points", "the same point appears twice")
    return tuple(expanded)
