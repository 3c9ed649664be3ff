"""``python -m mission vehicle`` as a user runs it (in this process: the same entry point): the
responses' numbers as one JSON object and the figure."""

from __future__ import annotations

import json
import struct

from mission.cli import entry_point


def test_it_prints_the_responses_and_draws_them(capsys, tmp_path):
    figure = tmp_path / "responses.png"
    status = entry_point(["vehicle", "along", "--plot", str(figure)])
    captured = capsys.readouterr()
    assert status == 0, captured.err
    numbers = json.loads(captured.out)
    assert set(numbers) == {
        "step_overshoot_m",
        "step_settling_2cm_s",
        "step_tilt_max_deg",
        "gust_displacement_max_m",
        "gust_settling_2cm_s",
    }
    assert 0.05 < numbers["step_overshoot_m"]["model"] < 0.12  # PX4's gains overshoot a little
    header = figure.read_bytes()[:24]
    assert header[:8] == b"\x89PNG\r\n\x1a\n" and struct.unpack(">II", header[16:24])[0] > 800
