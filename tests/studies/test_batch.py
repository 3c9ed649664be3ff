"""``mission batch`` (Table 3's study): its statistics by hand, and a 3-seed paired Along batch
that resumes and leaves no process when stopped."""

from __future__ import annotations

import csv
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from mission.studies.table3 import compare, method_stats, table_markdown, table_rows
from tests.processes import ROOT


def _fake_rows() -> list[dict]:
    figures = {
        "ac": [(10, 200.0), (20, 210.0), (30, None)],
        "nac": [(40, 250.0), (50, 260.0), (60, 270.0)],
    }
    return [
        {
            "scenario": "along",
            "method": method,
            "seed": seed,
            "completed": time_s is not None,
            "completion_time_s": time_s,
            "multipath_steps_total": steps,
        }
        for method, runs in figures.items()
        for seed, (steps, time_s) in enumerate(runs)
    ]


def test_table_statistics_match_a_hand_computation():
    rows = _fake_rows()
    ac = method_stats([r for r in rows if r["method"] == "ac"])
    assert (ac.steps_mean, ac.steps_std) == (20.0, 10.0)
    assert ac.time_mean == 205.0 and ac.time_std == pytest.approx(50**0.5)
    assert ac.completion_rate == pytest.approx(2 / 3)
    steps = compare({0: 10, 1: 20, 2: 30}, {0: 40, 1: 50, 2: 60})
    assert steps.reduction_pct == pytest.approx(100 * (50 - 20) / 50)
    # three pairs, all with the same sign: the exact two-sided p is 2 / 2^3
    assert steps.p_value == pytest.approx(0.25) and steps.pairs == 3
    times = compare({0: 200.0, 1: 210.0, 2: None}, {0: 250.0, 1: 260.0, 2: 270.0})
    assert times.pairs == 2 and times.reduction_pct == pytest.approx(100 * 50 / 255)
    table = table_rows(rows)
    assert [(r["method"], r["steps_reduction_pct"]) for r in table] == [("ac", 60.0), ("nac", None)]
    assert (table[0]["pairs"], table[0]["time_pairs"]) == (3, 2)


def test_a_p_value_from_too_few_pairs_says_so():
    """Below six pairs no two-sided signed-rank p reaches 0.05 (2 / 2^n): the table says the
    pairs are too few; with fifteen it gives p plainly."""
    few = table_markdown(table_rows(_fake_rows()))
    assert "3 pairs: too few" in few and "2 pairs: too few" in few
    ac = {seed: 10.0 + seed for seed in range(15)}
    nac = {seed: 40.0 + seed for seed in range(15)}
    assert compare(ac, nac).p_value < 0.001
    row = {
        "scenario": "s", "method": "ac", "runs": 15, "steps_mean": 17.0, "steps_std": 4.5,
        "completion_time_mean_s": None, "completion_time_std_s": None, "completion_rate": 1.0,
        "steps_reduction_pct": 64.8, "steps_wilcoxon_p": 0.0001, "time_reduction_pct": None,
        "time_wilcoxon_p": None, "pairs": 15, "time_pairs": 0,
    }  # fmt: skip
    text = table_markdown([row])
    assert "-64.8 % (p = 0.0001) |" in text and "too few" not in text


def _batch(out: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [
            sys.executable,
            "-m",
            "mission",
            "batch",
            "along",
            "--trials",
            "2",
            "--jobs",
            "2",
            "--out",
            str(out),
        ],
        capture_output=True,
        text=True,
        timeout=1200,
        cwd=ROOT,
    )


@pytest.mark.slow
def test_a_two_seed_paired_along_batch_ac_beats_nac_on_every_seed(tmp_path):
    result = _batch(tmp_path)
    assert result.returncode == 0, result.stderr
    rows = list(csv.DictReader((tmp_path / "results.csv").open()))
    steps = {(r["method"], int(r["seed"])): int(r["multipath_steps_total"]) for r in rows}
    assert sorted(steps) == [(m, s) for m in ("ac", "nac") for s in range(2)]
    for seed in range(2):
        assert steps[("ac", seed)] < steps[("nac", seed)], steps
    assert all(r["completed"] == "True" for r in rows)
    before = (tmp_path / "results.csv").read_bytes()
    again = _batch(tmp_path)  # everything finished: nothing runs, nothing changes
    assert again.returncode == 0, again.stderr
    assert "0 runs finished, 4 already done" in again.stdout
    assert (tmp_path / "results.csv").read_bytes() == before
    table = (tmp_path / "table.md").read_text()
    assert "| along | AC | 2 |" in table and "2 pairs: too few" in table
    assert (tmp_path / "boxplots.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.slow
def test_a_terminated_batch_leaves_no_process_behind(tmp_path):
    out = tmp_path / "stopped"
    batch = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "mission",
            "batch",
            "along",
            "--trials",
            "2",
            "--methods",
            "ac",
            "--out",
            str(out),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not list(out.glob("runs/*/gcs.tlog")):
            time.sleep(0.1)
        assert list(out.glob("runs/*/gcs.tlog")), "a run got going"
        batch.send_signal(signal.SIGTERM)
        stdout, _ = batch.communicate(timeout=60)
    finally:
        if batch.poll() is None:
            batch.kill()
    assert batch.returncode == 130 and "run it again to resume" in stdout
    left = subprocess.run(["pgrep", "-f", "--", str(out)], capture_output=True, text=True)
    assert left.stdout.split() == []
    assert not list(out.glob("runs/*/summary.json"))  # nothing half-finished counts as done


def test_a_batch_gives_runs_an_mpc_helper_only_where_each_has_a_core_for_it():
    from mission.studies.local_engine import helper_has_a_core

    assert helper_has_a_core(1, 2) and helper_has_a_core(2, 4)
    assert not helper_has_a_core(2, 2) and not helper_has_a_core(1, 1)
