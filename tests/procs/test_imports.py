"""What a run imports: heavy packages only where they are used (every process of every run
pays for an import at start-up)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.processes import ROOT

pytestmark = pytest.mark.slow  # a fresh interpreter


def test_a_run_without_inspections_imports_no_scipy():
    """scipy.sparse (and numpy.f2py, which scipy's array-API shim pulls in) cost every run
    ~0.4 s of start-up when only routes for inspections use them: the preflight, the ground
    station's context and its cycle, and the vehicles import none of it for Along."""
    code = (
        "import sys, numpy as np;"
        "from mission.commands import run; from mission.runs import orchestrator;"
        "from ground_station import cli, station; from ground_station.control import cycle;"
        "from vehicle_sim import server;"
        "from mission.world.model import World;"
        "from mission.link.plan_check import check_recall_in_time;"
        "from mission.link.plan_files import read_plan;"
        "from ground_station.control.run_context import build_run_context;"
        "world = World.load('along').known(); check_recall_in_time(world);"
        "plan = read_plan(world.scenario);"
        "points = {'work': plan.work, **{f'support-{n + 1}': p"
        " for n, p in enumerate(plan.supports)}};"
        "build_run_context(world, points, True, 0);"
        "print(sorted(m for m in ('scipy', 'numpy.f2py') if m in sys.modules))"
    )
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=300
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "[]"
