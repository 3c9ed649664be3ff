"""The two-zone scenario flown: with N = 5 supports, two or more enter multipath, and the
summary's diagnostics cover every support."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from tests.processes import ROOT


@pytest.mark.slow
def test_in_the_two_zone_scenario_two_or_more_supports_fly_through_multipath(tmp_path):
    out = tmp_path / "run"
    subprocess.run(
        [sys.executable, "-m", "mission", "run", "twozone", "--method", "nac", "--out", str(out)],
        check=True,
        capture_output=True,
        timeout=600,
        cwd=ROOT,
    )
    summary = json.loads((out / "summary.json").read_text())
    assert summary["completed"]
    in_multipath = [name for name, steps in summary["multipath_steps"].items() if steps > 0]
    assert len(in_multipath) >= 2, summary["multipath_steps"]
    supports = summary["diagnostics"]["supports"]
    assert sorted(supports) == [f"support-{n}" for n in range(1, 6)]
    for name, steps in summary["multipath_steps"].items():
        assert supports[name]["zone_cycles"] == steps  # the same truth, the same cycles
