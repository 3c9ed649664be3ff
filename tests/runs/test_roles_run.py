"""Dynamic roles in a real run (issue 33): on the piers scenario the ground station uses the
work UAV's own fix in the open (most of its first 90 s, at the west pier and the deck's south
edge), each where G expects at most 0.3 m, and the summary counts the verdicts."""

from __future__ import annotations

import json

import pytest

from tests.processes import mission


@pytest.mark.slow
def test_in_the_open_the_work_uav_is_localized_by_its_own_fix_too(tmp_path):
    scenario = tmp_path / "piers-dynamic.yaml"
    scenario.write_text(
        "extends: piers\nname: piers-dynamic\nroles: {policy: dynamic}\nrun: {timeout_s: 90}\n"
    )
    result = mission("run", str(scenario), "--out", str(tmp_path / "run"))
    assert result.returncode == 0, result.stderr
    records = [json.loads(line) for line in (tmp_path / "run" / "records.jsonl").open()]
    verdicts = [r["own_fix"] for r in records]
    used = [v for v in verdicts if v["used"]]
    assert len(used) > len(records) / 2  # the west pier's face and the south edge: open sky
    assert all(v["sigma_m"] <= 0.3 for v in used)
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    counts = summary["diagnostics"]["own_fix_cycles"]
    assert counts["used"] == len(used) and sum(counts.values()) == len(records)
