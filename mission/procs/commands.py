"""The command lines this project starts of itself, written once."""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path


def mission_run_argv(
    scenario: str | Path,
    out: Path,
    method: str = "ac",
    seed: int = 0,
    mpc_helper: bool | None = None,
    extra: Sequence[str] = (),
) -> list[str]:
    """``python -m mission run SCENARIO --method M --seed S --out OUT`` with this
    interpreter; ``mpc_helper`` None leaves the helper to the run's own choice."""
    argv = [sys.executable, "-m", "mission", "run", str(scenario), "--method", method]
    argv += ["--seed", str(seed), "--out", str(out)]
    if mpc_helper is not None:
        argv.append("--mpc-helper" if mpc_helper else "--no-mpc-helper")
    return [*argv, *extra]
