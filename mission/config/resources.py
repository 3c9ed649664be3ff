"""What a scenario would ask of the machine, estimated before anything runs and refused with
one line naming the field, the estimate and the limit (``limits:`` in the scenario raises
it). A tiny voxel or a huge workspace would otherwise end in a MemoryError deep in a process,
and a tiny control period in a run that never finishes."""

from __future__ import annotations

import math
import os

from mission.config.errors import FieldProblem
from mission.config.settings import ControlSettings, Scenario

MAP_BYTES_PER_VOXEL = 96  # G, its initial copy, sigma_0, the build's visibility and geometry
# a cycle's particles: positions, their draws, every support's density and the correlation's
# copies (112.5 bytes measured at the peak of a fusion with three supports)
PARTICLE_BYTES, PARTICLE_BYTES_PER_SUPPORT = 48, 24


def check_resources(scenario: Scenario) -> None:
    """FieldProblem for the first limit the scenario exceeds."""
    limits = scenario.limits
    voxels = map_voxels(scenario)
    if voxels > limits.max_map_voxels:
        raise FieldProblem(
            "map.voxel_size_m",
            f"{scenario.map.voxel_size_m:g} m over the {_size(scenario)} workspace makes "
            f"{voxels:,} voxels "
            f"(~{_gb(voxels * MAP_BYTES_PER_VOXEL)}); limits.max_map_voxels is "
            f"{limits.max_map_voxels:,}",
        )
    memory = _physical_memory()
    need = voxels * MAP_BYTES_PER_VOXEL
    if memory is not None and need > limits.max_memory_fraction * memory:
        raise FieldProblem(
            "map.voxel_size_m",
            f"the map needs ~{_gb(need)}, more than limits.max_memory_fraction "
            f"({limits.max_memory_fraction:g}) of this machine's {_gb(memory)}",
        )
    window = mpc_window_voxels(scenario)
    if window > limits.max_mpc_window_voxels:
        raise FieldProblem(
            "map.voxel_size_m",
            f"{scenario.map.voxel_size_m:g} m gives each support MPC {window:,} voxels of G "
            f"(its NLP's parameters); limits.max_mpc_window_voxels is "
            f"{limits.max_mpc_window_voxels:,}",
        )
    _check_cycle_work(scenario)


def _check_cycle_work(scenario: Scenario) -> None:
    limits, fusion, control = scenario.limits, scenario.fusion, scenario.control
    particles = fusion.broad_particles + fusion.local_particles * scenario.task.supports
    if particles > limits.max_particles:
        raise FieldProblem(
            "fusion.broad_particles",
            f"{particles:,} particles a cycle (broad + local x supports); "
            f"limits.max_particles is {limits.max_particles:,}",
        )
    memory = _physical_memory()
    need = particles * (PARTICLE_BYTES + PARTICLE_BYTES_PER_SUPPORT * scenario.task.supports)
    if memory is not None and need > limits.max_memory_fraction * memory:
        raise FieldProblem(
            "fusion.broad_particles",
            f"{particles:,} particles a cycle need ~{_gb(need)}, more than "
            f"limits.max_memory_fraction ({limits.max_memory_fraction:g}) of this machine's "
            f"{_gb(memory)}",
        )
    if control.horizon_steps > limits.max_horizon_steps:
        raise FieldProblem(
            "control.horizon_steps",
            f"{control.horizon_steps} exceeds limits.max_horizon_steps "
            f"({limits.max_horizon_steps})",
        )
    cycles = math.ceil(scenario.run.timeout_s / control.t_cont_s)
    if cycles > limits.max_control_cycles:
        raise FieldProblem(
            "control.t_cont_s",
            f"{control.t_cont_s:g} s over run.timeout_s {scenario.run.timeout_s:g} s is up to "
            f"{cycles:,} control cycles; limits.max_control_cycles is "
            f"{limits.max_control_cycles:,}",
        )


def map_shape(scenario: Scenario) -> tuple[int, int, int]:
    """Voxels of G along x, y, z (as mission.world.grid.VoxelGrid.over counts them)."""
    size = scenario.map.voxel_size_m
    box = scenario.world.workspace
    edges = [hi - lo for lo, hi in zip(box.min_m, box.max_m)]
    return tuple(max(1, math.floor(edge / size + 1e-9)) for edge in edges)  # type: ignore[return-value]


def map_voxels(scenario: Scenario) -> int:
    """Voxels of G over the workspace."""
    return math.prod(map_shape(scenario))


def mpc_window_shape(
    control: ControlSettings, voxel_m: float, shape: tuple[int, ...]
) -> tuple[int, int, int]:
    """The cube of G around yhat_n a support MPC sees: everything its horizon can reach (U
    d_max) plus a voxel on each side, cut to the map."""
    reach = control.horizon_steps * control.d_max_support_m + voxel_m
    half = math.ceil(reach / voxel_m)
    return tuple(min(2 * half + 1, n) for n in shape)  # type: ignore[return-value]


def mpc_window_voxels(scenario: Scenario) -> int:
    """Voxels of G one support MPC sees."""
    shape = map_shape(scenario)
    return math.prod(mpc_window_shape(scenario.control, scenario.map.voxel_size_m, shape))


def _size(scenario: Scenario) -> str:
    box = scenario.world.workspace
    return " x ".join(f"{hi - lo:g}" for lo, hi in zip(box.min_m, box.max_m)) + " m"


def _physical_memory() -> int | None:
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return None


def _gb(size: float) -> str:
    return f"{size / 1e9:.1f} GB" if size >= 1e8 else f"{size / 1e6:.0f} MB"
