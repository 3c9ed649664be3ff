"""``mission plan`` writes beside the user's scenario or in the current directory, never into
the installed package."""

from __future__ import annotations

from pathlib import Path

import pytest

import mission
from mission.cli import entry_point
from mission.commands.plan import plan_directory
from mission.config.errors import InputError
from mission.config.scenario import load_scenario

PACKAGE = Path(mission.__file__).resolve().parent
SHIPPED = PACKAGE / "scenarios" / "plans" / "bridge"


def test_an_embedded_scenario_is_planned_into_the_current_directory(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    assert plan_directory(None, load_scenario("wall")) == tmp_path / "wall-plan"


def test_a_users_scenario_is_planned_beside_its_file(write_scenario, tmp_path, monkeypatch):
    monkeypatch.chdir("/")
    path = write_scenario("extends: along\nname: mine\n")
    scenario = load_scenario(str(path))
    assert Path(scenario.task.waypoints_dir).is_relative_to(PACKAGE)  # the shipped plan is read
    assert plan_directory(None, scenario) == path.parent / "mine-plan"
    assert plan_directory(tmp_path / "x", scenario) == tmp_path / "x"


def test_a_scenario_that_names_its_plan_is_planned_there(write_scenario):
    path = write_scenario("extends: along\nname: mine\ntask: {waypoints_dir: flights}\n")
    assert plan_directory(None, load_scenario(str(path))) == path.parent / "flights"


def test_the_package_is_refused_as_an_output(write_scenario):
    scenario = load_scenario(str(write_scenario("extends: along\n")))
    with pytest.raises(InputError, match=r"--out.*inside the installed package"):
        plan_directory(SHIPPED, scenario)


def test_replanning_gives_the_shipped_plans_byte_for_byte_and_leaves_them_alone(
    monkeypatch, tmp_path, capsys
):
    before = {p.name: p.read_bytes() for p in SHIPPED.iterdir()}
    monkeypatch.chdir(tmp_path)
    written = tmp_path / "along-plan"  # made by the command, and the figure may go into it
    assert entry_point(["plan", "along", "--plot", str(written / "p.png")]) == 0
    plans = {p.name: p.read_bytes() for p in written.iterdir() if p.suffix == ".waypoints"}
    assert sorted(plans) == sorted(before)
    assert {p.name: p.read_bytes() for p in SHIPPED.iterdir()} == before
    assert plans == before  # the same plan
    out = capsys.readouterr().out
    assert f"waypoints_dir: {written}" in out and f"wrote {written / 'p.png'}" in out
    assert "an Along zone for this plan" in out
    assert (written / "p.png").read_bytes()[:4] == b"\x89PNG"
    assert entry_point(["plan", "along", "--out", str(SHIPPED)]) == 2
