"""The resource limits a scenario must stay within: what one run may ask of this machine.

The defaults fit the development machine (2 cores, a few GB free) with a wide margin over the
embedded scenarios; a user with a bigger machine raises them in a scenario's ``limits:``."""

from __future__ import annotations

from dataclasses import dataclass

from mission.config.errors import FieldProblem


@dataclass(frozen=True)
class LimitSettings:
    """Upper bounds checked when a scenario loads (see :mod:`mission.config.resources`)."""

    max_map_voxels: int  # voxels of G over the workspace
    max_mpc_window_voxels: int  # voxels of G one support MPC sees (its NLP's parameters)
    max_particles: int  # fusion particles a cycle draws and scores
    max_horizon_steps: int  # MPC horizon U
    max_control_cycles: int  # timeout_s / t_cont_s
    max_memory_fraction: float  # of this machine's memory, for one process's map

    def __post_init__(self) -> None:
        for name in (
            "max_map_voxels",
            "max_mpc_window_voxels",
            "max_particles",
            "max_horizon_steps",
            "max_control_cycles",
        ):
            if getattr(self, name) < 1:
                raise FieldProblem(name, f"must be at least 1, got {getattr(self, name)}")
        if not 0 < self.max_memory_fraction <= 1:
            raise FieldProblem("max_memory_fraction", "must be in (0, 1]")
