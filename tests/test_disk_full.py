"""A full disk: each command that writes says so on one line naming the file, exits with
status 3, leaves none of what it began to write behind and no process running. On a small
tmpfs mounted for the test (skipped, saying why, where this machine does not let us mount
one)."""

from __future__ import annotations

import shutil
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.processes import ROOT, mission
from tests.shared_runs import SHORT

pytestmark = pytest.mark.slow  # real runs and studies

EXIT_NO_SPACE = 3


@pytest.fixture
def small_disk(tmp_path) -> Iterator[Path]:
    """A 2 MiB tmpfs (unmounted after)."""
    place = tmp_path / "disk"
    place.mkdir()
    mounted = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", str(place)],
        capture_output=True,
        text=True,
    )
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {mounted.stderr.strip() or 'not permitted'}")
    try:
        yield place
    finally:
        subprocess.run(["umount", "-l", str(place)], capture_output=True)


def _fill(disk: Path, leave_bytes: int) -> None:
    """Fill ``disk`` but ``leave_bytes``."""
    free = shutil.disk_usage(disk).free
    with (disk / "filler").open("wb") as filler:
        filler.write(b"\0" * max(0, free - leave_bytes))


def _files(disk: Path) -> set[str]:
    return {str(p.relative_to(disk)) for p in disk.rglob("*")}


def _refused(disk: Path, *argv: str, said: str = "no space left on device") -> str:
    before = _files(disk)
    result = mission(*argv)
    lines = result.stderr.strip().splitlines()
    assert result.returncode == EXIT_NO_SPACE, result.stderr
    assert lines and lines[-1].endswith(f": {said}"), lines
    assert "Traceback" not in result.stderr
    assert _files(disk) == before, "what it began to write is left"
    return lines[-1]


@pytest.mark.parametrize("room", [16_000, 300_000], ids=["at-once", "mid-run"])
def test_a_run_on_a_full_disk(small_disk, room):
    _fill(small_disk, room)
    line = _refused(small_disk, "run", "along", "--out", str(small_disk / "r"))
    assert str(small_disk / "r") in line
    left = subprocess.run(["pgrep", "-f", str(small_disk / "r")], capture_output=True)
    assert left.stdout == b"", "a process of the run is left"


def test_a_study_on_a_full_disk(small_disk):
    _fill(small_disk, 16_000)
    study = str(ROOT / "mission" / "studies" / "shipped" / "smoke.yaml")
    line = _refused(small_disk, "study", study, "--out", str(small_disk / "s"))
    assert str(small_disk / "s") in line


def _short(folder: Path) -> str:
    """The short mission (three work waypoints: planned in a third of Along's time)."""
    scenario = folder / "short-run.yaml"
    scenario.write_text(SHORT)
    return str(scenario)


def test_a_plan_on_a_full_disk(small_disk, tmp_path):
    _fill(small_disk, 6_000)  # room for a waypoint file or two, not four
    line = _refused(small_disk, "plan", _short(tmp_path), "--out", str(small_disk / "plan"))
    assert str(small_disk / "plan") in line


def test_a_plan_and_its_figure_or_neither(small_disk, tmp_path):
    _fill(small_disk, 4_000)  # the plan goes elsewhere, its figure onto the full disk
    plan, figure = tmp_path / "plan", str(small_disk / "p.png")
    line = _refused(small_disk, "plan", _short(tmp_path), "--out", str(plan), "--plot", figure)
    assert "p.png" in line
    assert not plan.exists(), "the plan was left without its figure"


def test_a_read_only_file_system_is_said_as_a_full_disk_is(small_disk, short_run):
    run = small_disk / "run"
    shutil.copytree(short_run[0], run, ignore=shutil.ignore_patterns("plots", "g"))
    subprocess.run(["mount", "-o", "remount,ro", str(small_disk)], check=True)
    line = _refused(small_disk, "analyze", str(run), said="read-only file system")
    assert str(run / "summary.json") in line


def test_a_recording_and_figures_on_a_full_disk(small_disk, short_run):
    run = small_disk / "run"
    shutil.copytree(short_run[0], run, ignore=shutil.ignore_patterns("plots"))
    _fill(small_disk, 20_000)
    _refused(small_disk, "view", str(run), "--save", str(small_disk / "v.rrd"))
    summary = (run / "summary.json").read_bytes()
    line = _refused(small_disk, "analyze", str(run), "--plots")
    assert str(run / "plots") in line
    assert (run / "summary.json").read_bytes() == summary
