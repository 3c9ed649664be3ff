"""Find, read, merge and validate scenario files.

A scenario is a YAML file layered on ``defaults.yaml``: mappings merge key by key, any other
value (lists included) replaces the default. ``extends: NAME|PATH`` layers a file on another
scenario instead of on the bare defaults. Embedded scenarios are loadable by name.
"""

from __future__ import annotations

import copy
from importlib import resources
from pathlib import Path
from typing import Any

import yaml

from mission.config.errors import FieldProblem, ScenarioError, read_text_file
from mission.config.resources import check_resources
from mission.config.settings import Scenario
from mission.config.settings_build import build_settings
from mission.config.signal_settings import SignalSettings

DEFAULTS_NAME = "defaults"
_MAX_EXTENDS_DEPTH = 8


def embedded_scenarios_dir() -> Path:
    """Directory holding the scenarios shipped inside the package."""
    return Path(str(resources.files("mission") / "scenarios"))


def embedded_scenario_names() -> list[str]:
    """Names of the embedded scenarios (``defaults`` excluded)."""
    return sorted(
        p.stem for p in embedded_scenarios_dir().glob("*.yaml") if p.stem != DEFAULTS_NAME
    )


def default_signal_settings() -> SignalSettings:
    """``world.gnss`` as defaults.yaml has it: what a scenario says of multipath when it says
    nothing (the ground station's scenario carries these, never a run's own)."""
    data = read_yaml_mapping(embedded_scenarios_dir() / f"{DEFAULTS_NAME}.yaml")
    return build_settings(SignalSettings, data["world"]["gnss"], "world.gnss")


def resolve_scenario_path(name_or_path: str) -> Path:
    """Return the file for an embedded scenario name or a path; raise ScenarioError if absent."""
    candidate = Path(name_or_path)
    if candidate.suffix in (".yaml", ".yml") or candidate.exists():
        if not candidate.is_file():
            raise ScenarioError(name_or_path, "", "no such scenario file")
        return candidate.resolve()
    embedded = embedded_scenarios_dir() / f"{name_or_path}.yaml"
    if embedded.is_file():
        return embedded
    names = ", ".join(embedded_scenario_names())
    raise ScenarioError(name_or_path, "", f"no such scenario (embedded ones: {names})")


def load_scenario(
    name_or_path: str,
    overrides: dict[str, Any] | None = None,
    layers: dict[str, Any] | None = None,
) -> Scenario:
    """Load, merge and validate a scenario given by embedded name or file path; ``overrides``
    (dotted keys, see :func:`resolved_mapping`) are layered on top (``layers``: the scenario's
    :func:`scenario_layers`, read already)."""
    path = resolve_scenario_path(name_or_path)
    merged = resolved_mapping(name_or_path, overrides, layers)
    merged["source"] = str(path)
    return scenario_from_mapping(merged, path)


def scenario_layers(name_or_path: str) -> dict[str, Any]:
    """A scenario's files merged (``extends`` down to the defaults), not yet validated: read
    once for the many points of a study."""
    merged = _load_layers(resolve_scenario_path(name_or_path), depth=0)
    merged.pop("extends", None)
    return merged


def resolved_mapping(
    name_or_path: str,
    overrides: dict[str, Any] | None = None,
    layers: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Every setting of a scenario, its layers merged, file references absolute; with
    ``overrides`` ({"fusion.rho_threshold": 0.5, ...}) merged last, as if written at the end of
    the scenario's own file (a relative path in one is relative to that file). ``layers``: the
    scenario's :func:`scenario_layers`, where they were read already (not changed here)."""
    path = resolve_scenario_path(name_or_path)
    merged = scenario_layers(name_or_path) if layers is None else layers
    if overrides:
        layer = nest_dotted(overrides)
        _absolutise_paths(layer, path.parent)
        return merge_settings(merged, layer)  # a copy
    return merged if layers is None else copy.deepcopy(layers)


def nest_dotted(overrides: dict[str, Any]) -> dict[str, Any]:
    """{"a.b": 1, "a.c": 2} -> {"a": {"b": 1, "c": 2}}."""
    nested: dict[str, Any] = {}
    for key, value in overrides.items():
        *parents, leaf = str(key).split(".")
        level = nested
        for part in parents:
            level = level.setdefault(part, {})
            if not isinstance(level, dict):
                raise ValueError(f"{key}: {part} is set as a value and as a mapping")
        level[leaf] = value
    return nested


def scenario_from_mapping(merged: dict[str, Any], path: Path) -> Scenario:
    """Validate a merged mapping (with its ``source``) as the scenario of file ``path``."""
    try:
        scenario = build_settings(Scenario, merged)
        check_resources(scenario)
    except FieldProblem as problem:
        raise ScenarioError(str(path), problem.field, problem.problem) from None
    _check_files(scenario, path)
    return scenario


def _load_layers(path: Path, depth: int) -> dict[str, Any]:
    if depth > _MAX_EXTENDS_DEPTH:
        raise ScenarioError(str(path), "extends", "too deep (is there a cycle?)")
    data = read_yaml_mapping(path)
    _absolutise_paths(data, path.parent)
    if path.name == f"{DEFAULTS_NAME}.yaml" and path.parent == embedded_scenarios_dir():
        return data
    base_name = data.get("extends", DEFAULTS_NAME)
    if not isinstance(base_name, str):
        raise ScenarioError(str(path), "extends", "expected a scenario name or path")
    if base_name == DEFAULTS_NAME:
        base_path = embedded_scenarios_dir() / f"{DEFAULTS_NAME}.yaml"
    else:
        base_ref = Path(base_name)
        if not base_ref.is_absolute() and (path.parent / base_ref).is_file():
            base_name = str(path.parent / base_ref)
        try:
            base_path = resolve_scenario_path(base_name)
        except ScenarioError as error:
            raise ScenarioError(str(path), "extends", f"{error.problem}: {base_name}") from None
    base = _load_layers(base_path, depth + 1)
    return merge_settings(base, data)


# libyaml's parser when PyYAML has it (10x faster: every process reads the scenario at
# start-up), with the same safe constructors; the pure-Python one otherwise, and for errors,
# whose wording is its own ("expected ',' or ']', but got '<stream end>'").
# Both refuse a key written twice in one mapping (YAML says keys are unique; PyYAML keeps the
# last, so a second, empty ``faults:`` would silently drop the first).


def _unique_keys(loader: type) -> type:
    class UniqueKeyLoader(loader):  # type: ignore[misc, valid-type]
        def construct_mapping(self, node: Any, deep: bool = False) -> Any:
            if isinstance(node, yaml.MappingNode):
                seen: set[Any] = set()
                for key_node, _ in node.value:
                    if key_node.tag == "tag:yaml.org,2002:merge":
                        continue
                    key = self.construct_object(key_node, deep=True)
                    try:
                        duplicate = key in seen
                    except TypeError:  # an unhashable key: the constructor's own error follows
                        continue
                    if duplicate:
                        raise yaml.constructor.ConstructorError(
                            None, None, f"the key {key!r} is written twice", key_node.start_mark
                        )
                    seen.add(key)
            return super().construct_mapping(node, deep=deep)

    return UniqueKeyLoader


_FAST_SAFE_LOADER = _unique_keys(getattr(yaml, "CSafeLoader", yaml.SafeLoader))
_SAFE_LOADER = _unique_keys(yaml.SafeLoader)


def _safe_load(text: str) -> Any:
    try:
        return yaml.load(text, Loader=_FAST_SAFE_LOADER)
    except yaml.YAMLError:
        return yaml.load(text, Loader=_SAFE_LOADER)


def read_yaml_mapping(path: Path) -> dict[str, Any]:
    """Parse a YAML file that must hold a mapping; errors name the file, line and column."""
    text = read_text_file(path, ScenarioError)
    try:
        data = _safe_load(text)
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(error, "problem", None) or str(error).splitlines()[0]
        raise ScenarioError(str(path), where, f"invalid YAML: {problem}") from None
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise ScenarioError(str(path), "", "the file must hold a mapping of settings")
    return data


def merge_settings(base: dict[str, Any], override: dict[str, Any]) -> dict[str, Any]:
    """Deep-merge ``override`` onto ``base``: mappings merge, everything else replaces."""
    merged = copy.deepcopy(base)
    for key, value in override.items():
        if isinstance(value, dict) and isinstance(merged.get(key), dict):
            merged[key] = merge_settings(merged[key], value)
        else:
            merged[key] = copy.deepcopy(value)
    return merged


def _absolutise_paths(data: dict[str, Any], directory: Path) -> None:
    """Make file references relative to the file that names them."""
    structure = _get(data, "world", "structure")
    if isinstance(structure, dict) and isinstance(structure.get("mesh_file"), str):
        structure["mesh_file"] = str((directory / structure["mesh_file"]).resolve())
    task = data.get("task")
    if isinstance(task, dict) and isinstance(task.get("waypoints_dir"), str):
        task["waypoints_dir"] = str((directory / task["waypoints_dir"]).resolve())
    sky = data.get("sky")
    if isinstance(sky, dict) and isinstance(sky.get("table"), str) and sky["table"] != "builtin":
        sky["table"] = str((directory / sky["table"]).resolve())


def _get(data: dict[str, Any], *keys: str) -> Any:
    for key in keys:
        if not isinstance(data, dict):
            return None
        data = data.get(key)  # type: ignore[assignment]
    return data


def _check_files(scenario: Scenario, path: Path) -> None:
    mesh = scenario.world.structure.mesh_file
    if mesh is not None and not Path(mesh).is_file():
        raise ScenarioError(str(path), "world.structure.mesh_file", f"no such file: {mesh}")
    table = scenario.sky.table
    if table != "builtin" and not Path(table).is_file():
        raise ScenarioError(str(path), "sky.table", f"no such file: {table}")
