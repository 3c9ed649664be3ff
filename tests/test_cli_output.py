"""What the command line prints reads as text."""

from __future__ import annotations

import pytest

from mission.commands.run import run_line

SUMMARY = {
    "completed": True,
    "completion_time_s": 254.5,
    "control_cycles": 509,
    "multipath_steps": {"support-1": 13, "support-2": 1, "support-3": 0},
    "multipath_steps_total": 14,
    "work_error_m": {"mean": 0.1408, "p95": 0.2686, "max": 0.6355},
    "wall_time_s": 4.21,
    "realtime_factor": 60.49,
}


def test_the_end_of_run_line_is_text_not_a_python_repr():
    line = run_line(SUMMARY, 900.0)
    assert line == (
        "completed at 254.5 s; 509 cycles; steps in multipath 14 (support-1 13, support-2 1, "
        "support-3 0); work UAV error mean 0.1408 m; wall 4.2 s, 60x real time"
    )
    assert "{" not in line and "'" not in line


def test_a_run_that_did_not_complete_or_estimate_says_so():
    summary = {**SUMMARY, "completed": False, "completion_time_s": None}
    summary["work_error_m"] = {"mean": None, "p95": None, "max": None}
    line = run_line(summary, 900.0)
    assert line.startswith("NOT completed within 900 s;")
    assert "work UAV error no estimate" in line


def test_a_stopped_run_says_why_and_every_run_says_how_close_it_came():
    safety = {
        "closest_approach_m": {"work/support-1": 2.85, "support-1/support-2": 3.4},
        "least_clearance_m": {"work": 0.9, "support-1": 0.54},
    }
    summary = {**SUMMARY, "completed": False, "completion_time_s": None, "safety": safety}
    summary["stopped"] = "support-1 crashed at 22.5 s"
    line = run_line(summary, 900.0)
    assert line.startswith("STOPPED: support-1 crashed at 22.5 s;")
    assert line.endswith("; closest approach 2.85 m, least clearance 0.54 m")


def test_real_time_at_1x_says_so_and_a_chosen_speed_up_does_not(capsys):
    from argparse import Namespace

    from mission.commands.common import realtime_speedup

    assert realtime_speedup(Namespace(realtime=True, speedup=None)) == 1.0
    assert "real time at 1x" in capsys.readouterr().err
    assert realtime_speedup(Namespace(realtime=True, speedup=10.0)) == 10.0
    assert capsys.readouterr().err == ""


def test_the_bench_names_each_group_as_it_goes(monkeypatch):
    import io

    from mission.bench import suite as bench
    from mission.bench.result import BenchResult

    row = BenchResult("made_up", 1.0, "x", "reference", None)
    monkeypatch.setattr(bench, "BENCHMARKS", {"quick": lambda: [row], "other": lambda: []})
    progress = io.StringIO()
    results = bench.run_benchmarks(["quick"], progress)
    assert results[1:] == [row]
    lines = progress.getvalue().splitlines()
    assert lines[0] == "bench: quick ..." and lines[1].startswith("bench: quick done in ")
    assert len(lines) == 2  # the group not asked for is not run


def test_a_run_whose_inspections_were_not_done_says_so_beside_the_work_uav_s_completion():
    reached = {
        "work": {"reached": 14, "of": 14},
        "support-1": {"reached": 3, "of": 3},
        "support-2": {"reached": 1, "of": 4},
    }
    line = run_line({**SUMMARY, "roles": {"waypoints_reached": reached}}, 900.0)
    assert line.startswith(
        "work task completed at 254.5 s, inspections NOT done within 900 s (support-2); 509 cycles;"
    )


def test_a_run_with_inspections_says_when_each_task_was_done():
    """Piers: the work UAV's task at 389 s, the last inspection at 467 s (934 cycles)."""
    reached = {"work": {"reached": 24, "of": 24}, "support-1": {"reached": 4, "of": 4}}
    roles = {"waypoints_reached": reached, "all_done_s": 467.0}
    summary = {**SUMMARY, "completion_time_s": 389.0, "control_cycles": 934, "roles": roles}
    assert run_line(summary, 900.0).startswith(
        "work task completed at 389.0 s, every inspection done at 467.0 s; 934 cycles;"
    )


def test_version_says_the_package_and_the_commit(capsys):
    from mission.cli import entry_point
    from mission.procs.provenance import code_identity

    with pytest.raises(SystemExit) as stopped:
        entry_point(["--version"])
    assert stopped.value.code == 0
    said = capsys.readouterr().out.strip()
    code = code_identity()
    assert f"mission {code['version'] or 'unknown'}" in said
    if code["commit"]:
        assert code["commit"][:12] in said
