"""The benchmark's aggregation: medians over repeats and the verdicts against the targets
(the detached run is replaced by one with known timings; the timings themselves are what
``python -m mission bench`` measures)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from mission.bench import suite as bench
from mission.bench.result import format_table


@dataclass
class _Plan:
    solve_ms: float


def _run(solves: list[float], cycles: list[float]) -> SimpleNamespace:
    """A detached run whose cycles each plan one support."""
    outputs = [
        SimpleNamespace(support_plans={"support-1": _Plan(s)}, cycle_ms=c)
        for s, c in zip(solves, cycles)
    ]
    return SimpleNamespace(outputs=outputs, completed=True)


def test_gcs_rows_are_medians_over_repeats_with_verdicts(monkeypatch):
    import mission.bench.detached

    repeats = iter(
        [  # solves (ms) and cycle times (ms) of three repeats of the same run
            _run([1, 2, 3, 4, 100], [10, 10, 10, 30, 30]),
            _run([2, 3, 4, 5, 200], [20, 20, 20, 40, 40]),
            _run([9, 9, 9, 9, 9], [50, 50, 50, 50, 50]),
        ]
    )
    monkeypatch.setattr(
        mission.bench.detached, "run_detached", lambda *args, **kwargs: next(repeats)
    )
    monkeypatch.setattr(bench, "scipy_over_casadi", lambda *args: 12.0)
    monkeypatch.setattr(bench, "interpreted_over_compiled", lambda *args: 4.5)
    rows = {r.name: r for r in bench.bench_ground_station(cycles=5, repeats=3)}
    # per-repeat medians 3, 4, 9 -> 4; p95s (linear) 80.8, 161, 9 -> 80.8; cycles 10, 20, 50 -> 20
    assert rows["support_mpc_solve_ms_median"].value == pytest.approx(4.0)
    assert rows["support_mpc_solve_ms_median"].ok
    assert rows["support_mpc_solve_ms_p95"].value == pytest.approx(80.8)
    assert not rows["support_mpc_solve_ms_p95"].ok
    assert rows["gcs_cycle_ms_median"].value == pytest.approx(20.0)
    assert rows["gcs_cycle_ms_median"].ok
    assert rows["scipy_over_casadi_ratio"].value == 12.0
    assert rows["scipy_over_casadi_ratio"].ok
    assert rows["interpreted_over_compiled_ratio"].value == 4.5
    assert rows["interpreted_over_compiled_ratio"].ok is None  # a reference, no target
    with pytest.raises(StopIteration):  # exactly three repeats were run
        next(repeats)


def test_run_rows_take_the_median_factor_and_estimate_the_batch_as_it_runs(monkeypatch):
    """Three Along AC runs as `mission run` makes them; then one run per scenario and method
    as a two-job batch makes them on this machine (helper only with a core for each)."""
    import os

    factors = iter([20.0, 51.0, 55.0])  # median 51: not the first, last or mean
    flying = iter([45.0, 40.0, 30.0])  # median 40: 0.78 of 51
    calls = []

    def fake_run(scenario, method, out, mpc_helper=None):
        calls.append((scenario, method, mpc_helper))
        if scenario.endswith("along-multicopter.yaml"):
            text = Path(scenario).read_text()
            assert "dynamics: multicopter" in text and "speed_m_s: 3.0" in text
            return {"realtime_factor": next(flying), "wall_time_s": 12.0}
        if len(calls) <= 6:  # the supports' CPU: 250, 600 and 900 us a step of 500
            used = {1: 0.125, 3: 0.3, 5: 0.45}[len(calls)]
            cpu = {"orchestrator": 9.0, "work": 9.0, **{f"support-{n}": used for n in (1, 2, 3)}}
            return {
                "realtime_factor": next(factors), "wall_time_s": 9.0, "cpu_s": cpu,
                "control_cycles": 500,
            }  # fmt: skip
        return {"realtime_factor": 1.0, "wall_time_s": {"along": 10.0, "wall": 12.0}[scenario]}

    monkeypatch.setattr(bench, "run_as_command", fake_run)
    batches = []

    def fake_batch(runs, out, jobs, mpc_helper):
        batches.append((list(runs), jobs, mpc_helper))
        for scenario, method in runs:
            fake_run(scenario, method, out, mpc_helper)
        return 22.0  # two rounds of two runs

    monkeypatch.setattr(bench, "batch_wall_s", fake_batch)
    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    used = iter([0.0, 4.0, 4.0, 9.0, 9.0, 12.0])  # CPU seconds around each run: 4, 5, 3
    monkeypatch.setattr(bench, "children_cpu_s", lambda: next(used))
    monkeypatch.setattr(bench, "python_loop_s", lambda repeats=5: 0.292)  # half as fast
    rows = {r.name: r for r in bench.bench_runs(trials=15, jobs=2, repeats=3)}
    factor = rows["realtime_factor_lockstep"]
    assert factor.value == 51.0 and factor.target == ">= 50" and factor.ok  # 100 x 0.146 / 0.292
    assert rows["run_cpu_s"].value == 4.0 and rows["run_cpu_s"].ok is None  # judged by the floor
    assert rows["vehicle_cpu_per_step_us"].value == pytest.approx(600.0)  # the supports only
    assert rows["table3_wall_s_estimate"].target == "<= 300"
    assert [c[0] for c in calls[:6:2]] == ["along"] * 3  # alternating with the multicopter
    multicopter = rows["realtime_factor_multicopter"]
    assert multicopter.value == 40.0 and not multicopter.ok  # 40 < 0.8 x 51
    assert calls[6:] == [
        ("along", "ac", False),
        ("along", "nac", False),
        ("wall", "ac", False),
        ("wall", "nac", False),
    ]
    assert batches == [
        ([("along", "ac"), ("along", "nac"), ("wall", "ac"), ("wall", "nac")], 2, False)
    ]
    assert rows["table3_wall_s_estimate"].value == pytest.approx(15 * 22.0)
    assert not rows["table3_wall_s_estimate"].ok  # 330 s > 150 s x 0.292 / 0.146


def test_every_invocation_starts_with_the_machines_speed_without_a_verdict(monkeypatch):
    monkeypatch.setattr(
        bench, "BENCHMARKS", {"world": lambda: [bench.BenchResult("x", 1.0, "s", "<= 2", True)]}
    )
    rows = bench.run_benchmarks(["world"])
    assert [r.name for r in rows] == ["machine_python_loop_s", "x"]
    assert rows[0].ok is None and 0 < rows[0].value < 60
    table = format_table(rows).splitlines()
    assert table[1].split()[-2:] == ["reference", "-"]
    assert table[2].split()[-1] == "yes"


def test_the_study_bench_reports_runs_per_hour_core_use_and_the_ray_to_local_ratio(monkeypatch):
    from mission.bench import study as bench_study

    walls = iter([72.0, 75.6])  # local, then Ray
    monkeypatch.setattr(bench_study, "_wall", lambda spec, out, engine: next(walls))
    used = iter([10.0, 140.0])  # the runs' CPU seconds: 130 in 72 s on two cores
    monkeypatch.setattr(bench_study, "children_cpu_s", lambda: next(used))
    monkeypatch.setattr(bench_study.os, "cpu_count", lambda: 2)
    rows = {r.name: r for r in bench_study.bench_studies()}
    assert rows["study_runs_per_hour"].value == pytest.approx(20 / 72.0 * 3600)
    core_use = rows["study_core_use"]
    assert core_use.value == pytest.approx(130 / 144) and core_use.ok
    ratio = rows["ray_over_local_wall_ratio"]
    assert ratio.value == pytest.approx(1.05) and ratio.ok


def test_the_margins_rows_hold_the_run_with_margins_to_the_target(monkeypatch):
    from mission.bench import margins as bench_margins

    posed = {}
    monkeypatch.setattr(
        bench_margins, "_posed", lambda world, cycles: posed.setdefault(id(world), [world])
    )
    ratios = iter([(1.2, 1.3), (1.4, 1.8)])  # the run with margins, then the paper's form
    monkeypatch.setattr(bench_margins, "_ratios", lambda requests, paper, safe: next(ratios))
    rows = {r.name: r for r in bench_margins.bench_margins(cycles=3)}
    assert rows["support_mpc_margins_median_ratio"].ok
    assert rows["support_mpc_margins_p95_ratio"].ok is False
    assert rows["support_mpc_margins_p95_ratio_paper_run"].value == 1.8
    assert rows["support_mpc_margins_median_ratio_paper_run"].ok is None  # a reference
    margins = [w.scenario.control.min_separation_m for [w] in posed.values()]
    assert margins == [2.0, 0.0]  # posed with the defaults first, then in the paper's form


def test_every_benchmark_group_can_be_chosen_on_the_command_line():
    import argparse

    from mission.commands import bench as command

    parser = argparse.ArgumentParser()
    command.add_parser(parser.add_subparsers())
    for name in bench.BENCHMARKS:
        assert parser.parse_args(["bench", "--only", name]).only == [name]


def test_the_roles_row_is_the_median_of_the_paired_runs_ratios(monkeypatch):
    """Detached runs replaced by ones with known cycle times, a pair per repeat: each pair's
    medians (fixed 10, 20, 10; dynamic 11, 30, 20), the median of their ratios 1.5 (the ratio
    of the medians would read 2.0), the longest dynamic cycle; the two runs of a pair are
    stepped in turn, each pair started by the other policy than the last."""
    from mission.bench import detached, roles

    fixed = iter([[10.0, 10.0, 12.0], [20.0, 19.0, 21.0], [10.0, 10.0, 10.0]])
    dynamic = iter([[11.0, 11.0, 40.0], [30.0, 30.0, 30.0], [20.0, 20.0, 20.0]])
    order = []

    def fake(world, waypoints, adaptive, seed, max_cycles):
        policy = world.scenario.roles.policy
        times = next(dynamic if policy == "dynamic" else fixed)
        for t in times:
            order.append(policy)
            yield SimpleNamespace(cycle_ms=t), None, False

    monkeypatch.setattr(detached, "detached_cycles", fake)
    ratio, longest = roles.bench_roles(cycles=3, repeats=3)
    assert ratio.name == "dynamic_roles_cycle_ratio" and ratio.value == pytest.approx(1.5)
    assert ratio.ok is False
    assert longest.value == 40.0 and longest.ok is None
    assert order[:4] == ["fixed", "dynamic", "fixed", "dynamic"]
    assert order[6:10] == ["dynamic", "fixed", "dynamic", "fixed"]


def test_the_integrity_row_pairs_runs_with_the_monitor_on_and_off(monkeypatch):
    """As the roles row: medians off 10, 10, 10 and on 10.2, 11, 10.4: ratios 1.02, 1.1,
    1.04, their median 1.04, under the target."""
    from mission.bench import detached, integrity

    off = iter([[10.0, 10.0, 10.0]] * 3)
    on = iter([[10.2, 10.2, 9.0], [11.0, 11.0, 11.0], [10.4, 10.4, 10.4]])

    def fake(world, waypoints, adaptive, seed, max_cycles):
        times = next(on if world.scenario.integrity.enabled else off)
        for t in times:
            yield SimpleNamespace(cycle_ms=t), None, False

    monkeypatch.setattr(detached, "detached_cycles", fake)
    (ratio,) = integrity.bench_integrity(cycles=3, repeats=3)
    assert ratio.name == "integrity_cycle_ratio" and ratio.value == pytest.approx(1.04)
    assert ratio.ok is True


def test_the_floor_rows_are_the_detached_runs_cpu_and_plan_seconds(monkeypatch):
    """Three detached runs replaced by ones with known plans, the CPU clock by one that reads
    2, 5 and 3 s for them: medians 3 s of CPU and the plans' 0.25 s (of 0.1, 0.25, 0.4)."""
    from mission.bench import detached, floor

    runs = iter([_run([50, 50], [1, 1]), _run([100, 150], [1, 1]), _run([400], [1])])
    monkeypatch.setattr(detached, "run_detached", lambda *args, **kwargs: next(runs))
    clock = iter([0.0, 2.0, 10.0, 15.0, 20.0, 23.0])
    monkeypatch.setattr(floor.time, "process_time", lambda: next(clock))
    cpu, plans = floor.bench_floor(repeats=3)
    assert (cpu.name, cpu.value, cpu.ok) == ("detached_run_cpu_s", 3.0, None)
    assert (plans.name, plans.ok) == ("detached_plans_s", None)
    assert plans.value == pytest.approx(0.25)


def test_a_run_is_set_against_its_floor_read_in_the_same_invocation(monkeypatch):
    """run_cpu_s 4 s over detached_run_cpu_s 2.5 s: 1.6, the target; 4.1 s misses it; and
    without the floor in the invocation there is no ratio."""
    from mission.bench.result import BenchResult

    def rows(run_cpu, floor_cpu):
        found = [BenchResult("run_cpu_s", run_cpu, "s", "", None)]
        if floor_cpu is not None:
            found.append(BenchResult("detached_run_cpu_s", floor_cpu, "s", "reference", None))
        return bench.same_invocation_ratios(found)

    (met,) = rows(4.0, 2.5)
    assert met.name == "run_over_detached_cpu_ratio" and met.value == pytest.approx(1.6)
    assert met.ok and met.target == "<= 1.6"
    (missed,) = rows(4.1, 2.5)
    assert not missed.ok
    assert rows(4.0, None) == []


def test_a_vehicles_step_in_a_run_is_set_against_the_same_step_warm():
    from mission.bench.result import BenchResult

    in_run = BenchResult("vehicle_cpu_per_step_us", 600.0, "us", "reference", None)
    warm = BenchResult("vehicle_step_warm_us", 240.0, "us", "reference", None)
    (ratio,) = bench.same_invocation_ratios([in_run, warm])
    assert ratio.name == "vehicle_run_over_warm_ratio" and ratio.value == pytest.approx(2.5)
    assert ratio.ok is None
    assert bench.same_invocation_ratios([in_run]) == []


def test_a_runs_vehicle_cost_a_step_is_its_supports_mean_over_its_cycles():
    from mission.bench.vehicle_step import vehicle_cpu_per_step_us

    summary = {
        "cpu_s": {"orchestrator": 1.0, "work": 0.9, "support-1": 0.2, "support-2": 0.4},
        "control_cycles": 400,
    }
    assert vehicle_cpu_per_step_us(summary) == pytest.approx(750.0)
    assert math.isnan(vehicle_cpu_per_step_us({"control_cycles": 400}))  # not said: no row


def test_the_warm_step_flies_a_support_along_its_path_doing_a_runs_work(monkeypatch):
    """One flight of the warm step: the support takes every setpoint and estimate (none
    refused, no contact), publishes its sensors, and the time is per step."""
    from mission.bench import vehicle_step
    from vehicle_sim.vehicle import Vehicle

    published, stepped = [], []
    publish, step = Vehicle.publish, Vehicle.step

    def counting_publish(self, work):
        published.append(work)
        return publish(self, work)

    def counting_step(self, others=None):
        stepped.append(sorted(others))
        return step(self, others)

    monkeypatch.setattr(Vehicle, "publish", counting_publish)
    monkeypatch.setattr(Vehicle, "step", counting_step)
    assert vehicle_step._warm_step_us() > 0
    assert len(published) == len(stepped) > 100
    assert stepped[0] == ["support-2", "support-3", "work"]


def test_the_floor_refuses_a_detached_run_that_did_not_finish(monkeypatch):
    from mission.bench import detached, floor
    from mission.procs import machine_speed

    unfinished = _run([50], [1])
    unfinished.completed = False
    monkeypatch.setattr(detached, "run_detached", lambda *args, **kwargs: unfinished)
    monkeypatch.setattr(machine_speed, "python_loop_s", lambda repeats: 0.146)
    with pytest.raises(RuntimeError, match="did not finish in 1000 cycles"):
        floor.bench_floor(repeats=1)


def test_the_multipath_row_times_the_same_fixes_by_both_models_in_turn(monkeypatch):
    """Two fake worlds whose fixes cost 1 and 2 ms of (faked) CPU: 200 fixes cost 0.2 and
    0.4 s, made in turns by blocks of 50, the one asked for first."""
    from mission.bench import multipath

    clock = {"t": 0.0}
    cost = {"zones": 0.001, "geometry": 0.002}
    order = []

    class Fake:
        def __init__(self, name):
            self.name = name

        def gnss_fix(self, point, rng):
            clock["t"] += cost[self.name]
            if not order or order[-1] != self.name:
                order.append(self.name)

    monkeypatch.setattr(multipath.time, "process_time", lambda: clock["t"])
    worlds = {"zones": Fake("zones"), "geometry": Fake("geometry")}
    positions = np.zeros((200, 3))
    spent = multipath._time_fixes(worlds, positions, first="geometry")
    assert spent == pytest.approx({"zones": 0.2, "geometry": 0.4})
    assert order[:3] == ["geometry", "zones", "geometry"] and len(order) == 8  # blocks of 50


def test_a_batch_round_runs_jobs_at_a_time_as_whole_commands(tmp_path):
    """Four runs on two jobs: two at once (each waits for a partner at a barrier, so one at a
    time would never finish), each given its own folder and the helper choice."""
    import threading

    from mission.bench.run_command import batch_wall_s

    partners = threading.Barrier(2, timeout=10)
    made = []

    def run(scenario, method, out, mpc_helper):
        partners.wait()
        made.append((scenario, method, out.name, mpc_helper))
        return {}

    runs = [("along", "ac"), ("along", "nac"), ("wall", "ac"), ("wall", "nac")]
    assert batch_wall_s(runs, tmp_path, 2, False, run) > 0
    assert sorted(made) == sorted((s, m, f"batch-{s}-{m}", False) for s, m in runs)
