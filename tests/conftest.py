"""Shared fixtures (scenarios and worlds built once per session) and the fast lane's guard.

Every test that starts a process of the project (a vehicle, a ground station, a run, a forked
child, a Python interpreter) is marked ``slow``; ``pytest -m "not slow"`` runs the rest. The
guard below fails an unmarked test that starts one, so the fast lane stays fast.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from collections.abc import Callable
from pathlib import Path

import pytest

from mission.config.scenario import load_scenario
from mission.config.settings import Scenario
from mission.world.model import World


@pytest.fixture(scope="session")
def along() -> Scenario:
    """The embedded Along scenario."""
    return load_scenario("along")


@pytest.fixture(scope="session")
def along_world(along: Scenario) -> World:
    """The world of the embedded Along scenario."""
    return World(along)


@pytest.fixture(scope="session")
def short_run(tmp_path_factory) -> tuple[Path, Path]:
    """The short mission run once in lockstep, seed 0: (its folder, its scenario file); tests
    read it and never change it."""
    from tests.shared_runs import short_lockstep_run

    return short_lockstep_run(tmp_path_factory.mktemp("short"))


@pytest.fixture(scope="session")
def along_run(tmp_path_factory) -> Path:
    """``mission run along`` with the defaults, run once (AC, seed 0, lockstep): its folder;
    tests read it and never change it."""
    from tests.shared_runs import along_lockstep_run

    return along_lockstep_run(tmp_path_factory.mktemp("along"))


@pytest.fixture
def write_scenario(tmp_path: Path) -> Callable[[str, str], Path]:
    """Write a YAML scenario file into a temporary directory and return its path."""

    def write(text: str, name: str = "scenario.yaml") -> Path:
        path = tmp_path / name
        path.write_text(textwrap.dedent(text), encoding="utf-8")
        return path

    return write


def _is_python(program: object) -> bool:
    name = os.path.basename(str(program))
    return str(program) == sys.executable or name.startswith("python")


GUARD = pytest.StashKey[pytest.MonkeyPatch]()


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_setup(item: pytest.Item):
    """From a fast test's set-up (its fixtures included) to its teardown, forking or starting
    a Python interpreter fails the test: a test that starts processes is marked ``slow``."""
    if item.get_closest_marker("slow") is None:
        guard = pytest.MonkeyPatch()
        popen_init = subprocess.Popen.__init__

        def guarded_init(self, args, *more, **options):
            program = args[0] if isinstance(args, list | tuple) else str(args).split()[0]
            if _is_python(program):
                raise AssertionError(f"{item.nodeid} starts {program}: mark it slow")
            popen_init(self, args, *more, **options)

        def guarded_fork():
            raise AssertionError(f"{item.nodeid} forks: mark it slow")

        guard.setattr(subprocess.Popen, "__init__", guarded_init)
        guard.setattr(os, "fork", guarded_fork)
        item.stash[GUARD] = guard
    yield


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_teardown(item: pytest.Item):
    """The guard lifted once the test's own teardown has run."""
    yield
    guard = item.stash.get(GUARD, None)
    if guard is not None:
        guard.undo()


@pytest.fixture(scope="module", autouse=True)
def _figures_closed():
    """Tests that keep the figures they drew (to look into them) close them with their module."""
    yield
    if "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close("all")
