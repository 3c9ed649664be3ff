"""Shared fixtures: scenarios and worlds are built once per test session."""

from __future__ import annotations

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


@pytest.fixture
def write_scenario(tmp_path: Path) -> Callable[[str, str], Path]:
    """Write a YAML scenario file into a temporary directory and return its path."""

    def write(text: str, name: str = "scenario.yaml") -> Path:
        path = tmp_path / name
        path.write_text(textwrap.dedent(text), encoding="utf-8")
        return path

    return write
