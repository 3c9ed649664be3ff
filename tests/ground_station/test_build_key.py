"""The support MPC's libraries cached under a key from what they are built from: a cache hit
builds no expression, the key covers every module of the project whose functions the build
calls (a stale solver would otherwise load) and every argument, and a hit plans as the build
it stands for. The trace sees function calls: a constant read from an unlisted module would
pass it, so the builders take what they need from their arguments and their own modules."""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np

import ground_station
import mission
import vehicle_sim
from ground_station.support_mpc import margin_spaces, margins, nlp
from ground_station.support_mpc.margins import MARGIN_SPACES_BUILT_BY, Margins
from ground_station.support_mpc.mpc import SupportMpc
from mission.codegen.build_key import build_key, describe
from mission.codegen.casadi_cache import FunctionBuild, NlpBuild
from mission.world import grid
from mission.world.grid import VoxelGrid
from tests.extras import require_c_compiler

PROJECT = [Path(package.__file__).parent for package in (mission, ground_station, vehicle_sim)]


def _project_files_run_by(action) -> set[str]:
    """The project's source files whose code runs in ``action()``."""
    files: set[str] = set()

    def record(frame, event, arg):
        if event == "call":
            files.add(frame.f_code.co_filename)

    sys.setprofile(record)
    try:
        action()
    finally:
        sys.setprofile(None)
    return {f for f in files if any(Path(f).is_relative_to(root) for root in PROJECT)}


def _keyed(modules) -> set[str]:
    return {str(Path(module.__file__)) for module in modules}


def _window(along_world) -> VoxelGrid:
    mpc = SupportMpc(
        along_world.scenario.control, along_world.map_grid(), along_world.camera, others=3
    )
    return mpc._window_grid


def test_the_nlps_key_covers_every_module_their_build_runs(along_world, tmp_path, monkeypatch):
    control, window = along_world.scenario.control, _window(along_world)

    def build_and_generate():
        nlps, _ = nlp._symbolic_nlps(control, window, True, 3)
        monkeypatch.chdir(tmp_path)
        options = nlp.SOLVER_OPTIONS[control.mpc_solver]
        NlpBuild("support_mpc_near", control.mpc_solver, nlps["near"], options).generate("n.c")

    ran = _project_files_run_by(build_and_generate)
    assert {nlp.__file__, grid.__file__} < ran  # the trace sees the build
    assert ran <= _keyed(nlp.NLP_BUILT_BY), "a module the key misses"
    assert Path(tmp_path / "n.c").stat().st_size > 0


def test_the_margins_key_covers_every_module_their_build_runs(along_world, tmp_path, monkeypatch):
    control = along_world.scenario.control
    built = Margins(control, along_world.camera.structure, 3, compiled=False)
    rules = built.space_rules()

    def build_and_generate():
        function = margin_spaces.half_spaces_function(rules, control.horizon_steps)
        monkeypatch.chdir(tmp_path)
        FunctionBuild(function).generate("m.c")

    ran = _project_files_run_by(build_and_generate)
    assert margin_spaces.__file__ in ran  # the trace sees the build
    assert ran <= _keyed(MARGIN_SPACES_BUILT_BY), "a module the key misses"


CHOICES = {"mpc_solver": ("fatrop", "ipopt"), "los_penalty": ("paper", "visible-point")}


def _changed(name, value):
    """Another value of a setting's type (another of its choices for a choice)."""
    if name in CHOICES:
        return next(choice for choice in CHOICES[name] if choice != value)
    if isinstance(value, bool):
        return not value
    if isinstance(value, int | float):
        return value + 1
    return None


def test_every_argument_the_build_takes_changes_the_key(along_world):
    """nlp_key, which build_support_nlp keys its libraries by: every setting of the control
    section, the window's origin, voxel and shape, the prior and the margins' slots."""
    control, window = along_world.scenario.control, _window(along_world)
    base = nlp.nlp_key(control, window, True, 3)
    assert nlp.nlp_key(control, window, True, 3) == base
    for field in dataclasses.fields(control):
        other = _changed(field.name, getattr(control, field.name))
        assert other is not None, f"a setting of a new type: {field.name}"
        changed = dataclasses.replace(control, **{field.name: other})
        assert nlp.nlp_key(changed, window, True, 3) != base, field.name
    moved = VoxelGrid(window.origin_m + 0.5, window.voxel_m, window.shape)
    finer = VoxelGrid(window.origin_m, window.voxel_m / 2, window.shape)
    wider = VoxelGrid(window.origin_m, window.voxel_m, (window.shape[0] + 1, *window.shape[1:]))
    for other_window in (moved, finer, wider):
        assert nlp.nlp_key(control, other_window, True, 3) != base
    assert nlp.nlp_key(control, window, False, 3) != base
    assert nlp.nlp_key(control, window, True, 2) != base


def test_a_modules_source_edited_is_another_key(along_world, tmp_path):
    source = tmp_path / "builder.py"
    source.write_text("X = 1\n")
    module = type(sys)("builder")
    module.__file__ = str(source)
    before = build_key([along_world.scenario.control], [module])
    source.write_text("X = 2\n")
    assert build_key([along_world.scenario.control], [module]) != before


def test_arrays_are_keyed_by_every_value_not_their_printed_form():
    values = np.zeros(5000)
    other = values.copy()
    other[2500] = 1e-12  # numpy's repr would print both as [0. 0. 0. ... 0. 0. 0.]
    assert describe(values) != describe(other)
    assert describe(values) == describe(values.copy())
    assert describe(values.astype(np.float32)) != describe(values)


def test_a_cache_hit_builds_no_expression_and_plans_the_same(along_world, monkeypatch):
    require_c_compiler()
    scn, grid, camera = along_world.scenario, along_world.map_grid(), along_world.camera
    sigma0 = along_world.sigma0_map().sigma_m
    first = SupportMpc(scn.control, grid, camera, sigma0, others=3)  # compiles into the cache

    def no_build(*args, **kwargs):
        raise AssertionError("a cache hit builds no expression")

    with monkeypatch.context() as hit:
        hit.setattr(nlp, "_symbolic_nlps", no_build)
        hit.setattr(margins, "half_spaces_function", no_build)
        again = SupportMpc(scn.control, grid, camera, sigma0, others=3)
    interpreted = SupportMpc(scn.control, grid, camera, sigma0, others=3, compiled=False)
    waypoints = np.array([[-12.0, -3.0, 7.0], [-9.0, -3.5, 7.0], [-6.0, -3.5, 7.5]] * 4)
    work = np.array([[-12.0, 2.0, 5.0]] * 12)
    g = np.asarray(sigma0, dtype=float)
    plans = [
        mpc.solve(waypoints[0] + 0.2, waypoints, work, np.arange(12), g, camera.observable)
        for mpc in (first, again, interpreted)
    ]
    np.testing.assert_array_equal(plans[0].path, plans[1].path)
    np.testing.assert_allclose(plans[2].path, plans[0].path, atol=1e-6)
