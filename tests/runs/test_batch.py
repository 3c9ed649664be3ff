"""``mission batch``: Table 3 statistics by hand, resuming, and a 3-seed paired Along batch."""

from __future__ import annotations

import csv
import io
import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from mission.runs.batch import BatchOptions, Trial, finished_summary, run_batch
from mission.runs.batch_table import (
    compare,
    method_stats,
    result_rows,
    table_markdown,
    table_rows,
)
from tests.processes import ROOT


def _summary(trial: Trial, steps: int, time_s: float | None) -> dict:
    return {
        "scenario": trial.scenario_name,
        "method": trial.method,
        "seed": trial.seed,
        "completed": time_s is not None,
        "completion_time_s": time_s,
        "control_cycles": 10,
        "multipath_steps": {"support-1": steps},
        "multipath_steps_total": steps,
        "work_error_m": {"mean": 0.1, "p95": 0.2, "max": 0.3},
        "wall_time_s": 1.0,
        "realtime_factor": 5.0,
        "mpc_solve_ms": {"median": 2.0, "p95": 4.0},
    }


def _fake_batch() -> tuple[list[Trial], dict[Trial, dict]]:
    trials, summaries = [], {}
    figures = {
        "ac": [(10, 200.0), (20, 210.0), (30, None)],
        "nac": [(40, 250.0), (50, 260.0), (60, 270.0)],
    }
    for method, runs in figures.items():
        for seed, (steps, time_s) in enumerate(runs):
            trial = Trial("along", "along", method, seed)
            trials.append(trial)
            summaries[trial] = _summary(trial, steps, time_s)
    return trials, summaries


def test_table_statistics_match_a_hand_computation():
    trials, summaries = _fake_batch()
    rows = result_rows(trials, summaries)
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
    few = table_markdown(table_rows(result_rows(*_fake_batch())))
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


def test_a_finished_batch_is_skipped_and_its_tables_rewritten(tmp_path):
    trials, summaries = _fake_batch()
    for trial, summary in summaries.items():
        run_dir = tmp_path / "runs" / trial.key
        run_dir.mkdir(parents=True)
        (run_dir / "summary.json").write_text(json.dumps(summary))
    progress = io.StringIO()
    result = run_batch(BatchOptions(trials, tmp_path, jobs=2), progress)
    assert result == {
        "finished": 0,
        "skipped": 6,
        "failed": [],
        "wall_time_s": result["wall_time_s"],
    }
    rows = list(csv.DictReader((tmp_path / "results.csv").open()))
    assert [(r["method"], r["seed"], r["multipath_steps_total"]) for r in rows][:2] == [
        ("ac", "0", "10"),
        ("ac", "1", "20"),
    ]
    assert (
        "| along | AC | 3 | 20.0 +/- 10.0 | 205.0 +/- 7.1 | 67 % | -60.0 % (p = 0.25; 3 pairs: too"
        in (tmp_path / "table.md").read_text()
    )
    assert (tmp_path / "boxplots.png").read_bytes()[:4] == b"\x89PNG"


def test_an_unfinished_or_foreign_run_directory_does_not_count(tmp_path):
    trial = Trial("along", "along", "ac", 4)
    assert finished_summary(tmp_path, trial) is None
    (tmp_path / "summary.json").write_text("{ half a summ")
    assert finished_summary(tmp_path, trial) is None
    (tmp_path / "summary.json").write_text(
        json.dumps(_summary(Trial("along", "along", "nac", 4), 1, 2.0))
    )
    assert finished_summary(tmp_path, trial) is None


@pytest.mark.slow
def test_rerunning_an_unfinished_run_starts_from_an_empty_directory(tmp_path):
    """What an interrupted run left (a partial tlog, no summary) is wiped before it reruns."""
    from mission.runs.batch import _start_run

    run_dir = tmp_path / "runs" / "along-ac-0"
    run_dir.mkdir(parents=True)
    (run_dir / "gcs.tlog").write_bytes(b"partial")
    missing = str(tmp_path / "no-such-scenario.yaml")  # the child fails at once: no real run
    process = _start_run(Trial(missing, "along", "ac", 0), run_dir, mpc_helper=False)
    assert process.wait(timeout=60) != 0
    assert sorted(path.name for path in run_dir.iterdir()) == ["mission.log"]
    assert "no-such-scenario.yaml" in (run_dir / "mission.log").read_text()


def _batch(out: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [
            sys.executable,
            "-m",
            "mission",
            "batch",
            "along",
            "--trials",
            "3",
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
def test_a_three_seed_paired_along_batch_ac_beats_nac_on_every_seed(tmp_path):
    result = _batch(tmp_path)
    assert result.returncode == 0, result.stderr
    rows = list(csv.DictReader((tmp_path / "results.csv").open()))
    steps = {(r["method"], int(r["seed"])): int(r["multipath_steps_total"]) for r in rows}
    assert sorted(steps) == [(m, s) for m in ("ac", "nac") for s in range(3)]
    for seed in range(3):
        assert steps[("ac", seed)] < steps[("nac", seed)], steps
    assert all(r["completed"] == "True" for r in rows)
    before = (tmp_path / "results.csv").read_bytes()
    again = _batch(tmp_path)  # everything finished: nothing runs, nothing changes
    assert again.returncode == 0, again.stderr
    assert "0 runs finished, 6 already done" in again.stdout
    assert (tmp_path / "results.csv").read_bytes() == before


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
    assert batch.returncode == 130 and "run again to resume" in stdout
    left = subprocess.run(["pgrep", "-f", "--", str(out)], capture_output=True, text=True)
    assert left.stdout.split() == []
    assert not list(out.glob("runs/*/summary.json"))  # nothing half-finished counts as done


def test_a_batch_gives_runs_an_mpc_helper_only_where_each_has_a_core_for_it():
    from mission.runs.batch import helper_has_a_core

    assert helper_has_a_core(1, 2) and helper_has_a_core(2, 4)
    assert not helper_has_a_core(2, 2) and not helper_has_a_core(1, 1)
