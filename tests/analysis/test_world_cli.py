"""``python -m mission world`` as a user runs it (in this process: the same entry point)."""

from __future__ import annotations

import json
import struct

import pytest

from mission.cli import entry_point


def _mission(capsys, *args: str) -> tuple[int, str, str]:
    """(exit status, stdout, stderr) of ``python -m mission ARGS``."""
    try:
        status = entry_point(list(args))
    except SystemExit as stop:  # argparse's usage errors
        status = stop.code
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def _report(capsys, *at: str) -> dict:
    status, out, err = _mission(capsys, "world", "along", "--at", *at)
    assert status == 0, err
    return json.loads(out)


def test_open_sky_point_prints_a_fix_near_open_sky_pdop(capsys):
    report = _report(capsys, "0", "-15", "8")
    assert set(report) == {"visible", "n_visible", "pdop", "sigma_gnss_m", "in_zone"}
    assert report["n_visible"] == len(report["visible"]) == 15
    assert report["pdop"] == pytest.approx(1.44, abs=0.01)
    assert report["sigma_gnss_m"] == pytest.approx(0.144, abs=0.001)
    assert report["in_zone"] is False


def test_point_under_the_deck_prints_no_fix(capsys):
    report = _report(capsys, "0", "0", "6")
    assert report["pdop"] is None and report["sigma_gnss_m"] is None
    assert report["n_visible"] < 4


def test_point_in_the_zone_is_flagged(along, capsys):
    zone = along.world.zones[0]
    center = [str((lo + hi) / 2) for lo, hi in zip(zone.min_m, zone.max_m)]
    assert _report(capsys, *center)["in_zone"] is True


def test_summary_and_plot(tmp_path, capsys):
    plot = tmp_path / "world.png"
    status, out, err = _mission(capsys, "world", "wall", "--plot", str(plot))
    assert status == 0, err
    assert "open-sky PDOP 1.44" in out
    assert "wall" in out
    header = plot.read_bytes()[:24]
    assert header[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = struct.unpack(">II", header[16:24])
    assert width >= 1000 and height >= 800


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["world", "nosuch"], "no such scenario"),
        (["world", "along", "--at", "0", "nan", "1"], "--at"),
        (["world", "along", "--plot", "/nonexistent/dir/w.png"], "no directory"),
        (["world", "along", "--plot", "w.jpg"], "must end in .png"),
        (["world", "along", "--at", "1", "2"], "expected 3 argument"),
    ],
)
def test_bad_arguments_exit_2_with_one_line(args, needle, capsys):
    status, _, err = _mission(capsys, *args)
    assert status == 2
    assert needle in err
    assert err.count("\n") == 1


@pytest.mark.slow
def test_the_command_runs_as_a_process_too():
    import subprocess
    import sys

    result = subprocess.run(
        [sys.executable, "-m", "mission", "world", "along", "--at", "0", "-15", "8"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["n_visible"] == 15


def test_a_geometry_world_reports_its_receiver_at_a_point(capsys):
    status, out, err = _mission(capsys, "world", "river", "--at", "0", "0", "7")
    assert status == 0, err
    multipath = json.loads(out)["multipath"]
    assert multipath["reflected"] == multipath["used"] and len(multipath["used"]) >= 5
    assert multipath["solution"] == "rtk-float"
    assert multipath["error_m"] == pytest.approx([0.0, 0.0, -14.0], abs=1e-3)  # the mirror


def test_the_multipath_map_is_drawn_and_names_its_worst_point(tmp_path, capsys):
    figure = tmp_path / "multipath.png"
    status, out, err = _mission(capsys, "world", "river", "--multipath-map", str(figure))
    assert status == 0, err
    assert "multipath  geometry" in out and f"wrote {figure} (worst error" in out
    assert "z = 7.5 m, under the structure: fix 100%, not carrier-fixed 100%" in out
    worst = float(out.split("worst error ")[1].split(" m")[0])
    assert 5.0 < worst < 60.0  # under the deck: the published 5-30 m, and a pier's corner
    header = figure.read_bytes()[:24]
    assert header[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_bad_multipath_map_path_is_refused_before_anything_is_computed(tmp_path, capsys):
    status, _, err = _mission(capsys, "world", "river", "--multipath-map", str(tmp_path / "m.txt"))
    assert status == 2 and "--multipath-map" in err and len(err.strip().splitlines()) == 1


def test_the_multipath_map_of_an_unplanned_scenario_slices_at_the_work_uavs_heights(
    write_scenario,
):
    from mission.analysis.multipath_plot import mission_heights
    from mission.config.scenario import load_scenario
    from mission.world.model import World

    path = write_scenario("extends: river\nname: unplanned\ntask: {waypoints_dir: nowhere}\n")
    assert mission_heights(World(load_scenario(str(path)))) == [7.0]
