"""``python -m mission world`` as a user runs it."""

from __future__ import annotations

import json
import struct
import subprocess
import sys

import pytest


def _mission(*args: str, check: bool = True) -> subprocess.CompletedProcess:
    result = subprocess.run(
        [sys.executable, "-m", "mission", *args], capture_output=True, text=True, timeout=120
    )
    if check:
        assert result.returncode == 0, result.stderr
    return result


def test_open_sky_point_prints_a_fix_near_open_sky_pdop():
    report = json.loads(_mission("world", "along", "--at", "0", "-15", "8").stdout)
    assert set(report) == {"visible", "n_visible", "pdop", "sigma_gnss_m", "in_zone"}
    assert report["n_visible"] == len(report["visible"]) == 15
    assert report["pdop"] == pytest.approx(1.44, abs=0.01)
    assert report["sigma_gnss_m"] == pytest.approx(0.144, abs=0.001)
    assert report["in_zone"] is False


def test_point_under_the_deck_prints_no_fix():
    report = json.loads(_mission("world", "along", "--at", "0", "0", "6").stdout)
    assert report["pdop"] is None and report["sigma_gnss_m"] is None
    assert report["n_visible"] < 4


def test_point_in_the_zone_is_flagged(along):
    zone = along.world.zones[0]
    center = [str((lo + hi) / 2) for lo, hi in zip(zone.min_m, zone.max_m)]
    report = json.loads(_mission("world", "along", "--at", *center).stdout)
    assert report["in_zone"] is True


def test_summary_and_plot(tmp_path):
    plot = tmp_path / "world.png"
    result = _mission("world", "wall", "--plot", str(plot))
    assert "open-sky PDOP 1.44" in result.stdout
    assert "wall" in result.stdout
    header = plot.read_bytes()[:24]
    assert header[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = struct.unpack(">II", header[16:24])
    assert width >= 1000 and height >= 800


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["world", "nosuch"], "no such scenario"),
        (["world", "along", "--at", "0", "nan", "1"], "--at"),
        (["world", "along", "--plot", "/nonexistent/dir/w.png"], "does not exist"),
        (["world", "along", "--plot", "w.jpg"], "must end in .png"),
        (["world", "along", "--at", "1", "2"], "expected 3 argument"),
    ],
)
def test_bad_arguments_exit_2_with_one_line(args, needle):
    result = _mission(*args, check=False)
    assert result.returncode == 2
    assert needle in result.stderr
    assert result.stderr.count("\n") == 1
