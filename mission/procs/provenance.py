"""Where a result came from: the code (its git commit, whether the tree held uncommitted
changes, the package's version), the packages that compute (casadi, numpy, scipy, pymavlink),
Python, the machine, and the numerical kernels in use (:mod:`mission.procs.numerics`).

A run's summary carries :func:`run_provenance`; a study's ``provenance.json`` carries
:func:`environment` as well.
"""

from __future__ import annotations

import platform
import subprocess
from importlib import metadata
from pathlib import Path
from typing import Any

from mission.procs.numerics import cpu_model, numerics_in_use

DISTRIBUTION = "bridge-uav-formation"
PACKAGES = ("casadi", "numpy", "scipy", "pymavlink")
_SOURCE_ROOT = Path(__file__).resolve().parents[2]  # the checkout holding mission/
GIT_TIMEOUT_S = 10.0


def run_provenance() -> dict[str, Any]:
    """What summary.json says of the code and the numerics that made the run."""
    return {**code_identity(), "numerics": numerics_in_use()}


def code_identity(root: Path = _SOURCE_ROOT) -> dict[str, Any]:
    """``commit`` (None outside a git checkout), ``dirty`` (tracked files changed since it;
    None where unknown) and the package's ``version``."""
    commit = _git(root, "rev-parse", "HEAD")
    status = _git(root, "status", "--porcelain", "--untracked-files=no") if commit else None
    return {
        "commit": commit,
        "dirty": None if status is None else bool(status),
        "version": _version(DISTRIBUTION),
    }


def last_commit_of(path: Path) -> str | None:
    """The last commit that changed ``path`` (followed across renames; None outside a git
    checkout or for a file git never had)."""
    path = path.resolve()
    root = _git(path.parent, "rev-parse", "--show-toplevel")
    if not root:
        return None
    found = _git(Path(root), "log", "-1", "--follow", "--format=%H", "--", str(path))
    return found or None


def environment() -> dict[str, Any]:
    """The packages' versions, Python's, and the machine (with its numerics)."""
    return {
        "packages": {name: _version(name) for name in PACKAGES},
        "python": platform.python_version(),
        "machine": {
            "system": platform.system(),
            "architecture": platform.machine(),
            "cpu": cpu_model(),
            "numerics": numerics_in_use(),
        },
    }


def _version(distribution: str) -> str | None:
    try:
        return metadata.version(distribution)
    except metadata.PackageNotFoundError:
        return None


def _git(root: Path, *arguments: str) -> str | None:
    """git's output in ``root`` (stripped), or None where there is no git or no checkout."""
    if not any((folder / ".git").exists() for folder in (root, *root.parents)):
        return None
    try:
        done = subprocess.run(
            ["git", "-C", str(root), *arguments],
            capture_output=True,
            text=True,
            timeout=GIT_TIMEOUT_S,
            check=False,
        )
    except (OSError, subprocess.TimeoutExpired):
        return None
    return done.stdout.strip() if done.returncode == 0 else None
