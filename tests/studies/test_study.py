"""The study driver around its engine: skipping what is done, results.csv, the report, and
a run's folder packed for the trip from a node (a stand-in engine writes the runs here; the
engines themselves are tested with real runs in test_engines.py)."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

from mission.studies import execute
from mission.studies.results import inclusion_rate
from mission.studies.runkeys import StudyRun
from mission.studies.spec import Point, StudySpec
from mission.studies.study import rewrite_report, run_study


def _summary(run: StudyRun) -> dict:
    steps = 10 + run.seed if run.method == "ac" else 40 + 3 * run.seed
    time_s = 250.0 + run.seed if run.method == "ac" else 260.0 + 2 * run.seed
    return {
        "scenario": run.scenario_name,
        "method": run.method,
        "seed": run.seed,
        "completed": True,
        "completion_time_s": time_s,
        "control_cycles": 500,
        "multipath_steps": {"support-1": steps},
        "multipath_steps_total": steps,
        "work_error_m": {"mean": 0.1, "p95": 0.2, "max": 0.3},
        "link_events": [],
        "diagnostics": {
            "supports": {"support-1": {"zone_cycles": steps, "fused_in_zone": steps // 10}},
            "empty_s_cycles": 1,
            "time_beyond_flight_s": time_s - 230.0,
        },
        "wall_time_s": 5.0,
        "decisions_digest": f"{run.scenario_name}-{run.point}-{run.method}-{run.seed}",
    }


class FakeEngine:
    """Writes each run's summary as `mission run` would, without running anything."""

    description = "fake engine"
    cores = 1

    def __init__(self, fail_seed: int | None = None, inexact_seed: int | None = None) -> None:
        self.ran: list[str] = []
        self.fail_seed = fail_seed
        self.inexact_seed = inexact_seed  # its run's lockstep did not hold

    def run(self, runs, runs_dir, keep, done) -> None:
        for run in runs:
            folder = runs_dir / run.folder
            execute.prepare(run, folder)
            self.ran.append(run.folder)
            if run.seed != self.fail_seed:
                summary = _summary(run)
                if run.seed == self.inexact_seed:
                    summary["lockstep"] = {"exact": False, "auto_steps": 4}
                (folder / "summary.json").write_text(json.dumps(summary))
            status = 0 if run.seed != self.fail_seed else 1
            done(run, execute.conclude(run, folder, status, "node-a", keep), 1.0)


def _spec(seeds=(0, 1, 2)) -> StudySpec:
    points = (Point((("map.eta", 0.3),)), Point((("map.eta", 0.6),)))
    return StudySpec("t", "A test.", Path("t.yaml"), ("along",), ("ac", "nac"), seeds, points, ())


def test_a_study_writes_its_results_and_report_and_a_rerun_skips_everything(tmp_path):
    engine = FakeEngine()
    outcome = run_study(_spec(), tmp_path, engine, progress=io.StringIO())
    assert (outcome.finished, outcome.skipped, outcome.failed) == (12, 0, [])
    rows = list(csv.DictReader((tmp_path / "results.csv").open()))
    assert [(r["map.eta"], r["method"], r["seed"]) for r in rows[:3]] == [
        ("0.3", "ac", "0"),
        ("0.3", "nac", "0"),
        ("0.3", "ac", "1"),
    ]
    assert rows[0]["node"] == "node-a" and rows[0]["inclusion_rate"] == "0.1"
    report = (tmp_path / "report.md").read_text()
    # AC - NAC over seeds 0..2: time (250 + s) - (260 + 2 s) = -10, -11, -12
    assert "| along | map.eta=0.3 | 3 | -11.0 (-4.2 %) [-12.0, -10.0] (p = 0.25) |" in report
    assert (tmp_path / "figures" / "metrics-vs-map.eta.png").is_file()
    assert "steps in multipath" in report and "closest approach" not in report  # none has it
    before = {p: p.read_bytes() for p in (tmp_path / "results.csv", tmp_path / "report.md")}
    progress = io.StringIO()
    again = run_study(_spec(), tmp_path, FakeEngine(), progress=progress)
    assert (again.finished, again.skipped) == (0, 12)
    assert "12 already finished" in progress.getvalue()
    first = io.StringIO()
    run_study(_spec(), tmp_path / "named", FakeEngine(), progress=first)
    assert "along-ac-0-" in first.getvalue() and " [map.eta=0.3]: " in first.getvalue()
    assert {p: p.read_bytes() for p in before} == before


def test_a_failed_run_is_reported_and_runs_again_next_time(tmp_path):
    outcome = run_study(_spec(), tmp_path, FakeEngine(fail_seed=1), progress=io.StringIO())
    assert len(outcome.failed) == 4 and outcome.finished == 8
    assert "8 of 12 runs finished, 4 failed" in (tmp_path / "report.md").read_text()
    engine = FakeEngine()
    run_study(_spec(), tmp_path, engine, progress=io.StringIO())
    assert len(engine.ran) == 4 and all("-1-" in name for name in engine.ran)


def test_a_run_whose_lockstep_did_not_hold_is_failed_and_made_again(tmp_path):
    progress = io.StringIO()
    outcome = run_study(_spec(), tmp_path, FakeEngine(inexact_seed=2), progress=progress)
    assert len(outcome.failed) == 4 and outcome.finished == 8
    assert "FAILED: NOT exact lockstep (auto steps 4): it may not reproduce" in progress.getvalue()
    engine = FakeEngine()
    run_study(_spec(), tmp_path, engine, progress=io.StringIO())
    assert sorted(folder.split("-")[2] for folder in engine.ran) == ["2"] * 4


def test_studies_sharing_a_runs_folder_make_a_common_run_once(tmp_path):
    shared = tmp_path / "runs"
    first = FakeEngine()
    run_study(_spec(seeds=(0, 1)), tmp_path / "a", first, progress=io.StringIO(), runs_dir=shared)
    second = FakeEngine()
    run_study(_spec(seeds=(1, 2)), tmp_path / "b", second, progress=io.StringIO(), runs_dir=shared)
    assert len(first.ran) == 8 and len(second.ran) == 4  # seed 1 is shared
    assert len(list((tmp_path / "b" / "results.csv").read_text().splitlines())) == 9


def test_a_runs_folder_packs_trims_and_unpacks_whole(tmp_path):
    folder = tmp_path / "run"
    (folder / "g").mkdir(parents=True)
    (folder / "g" / "G_00020.npy").write_bytes(b"g")
    for name in ("summary.json", "scenario.yaml", "gcs.tlog", "records.jsonl"):
        (folder / name).write_text(name)
    data = execute.pack(folder)
    execute.unpack(data, tmp_path / "copy")
    assert _tree(tmp_path / "copy") == _tree(folder)
    execute.trim(folder, "logs")
    assert "g/G_00020.npy" not in _tree(folder) and "gcs.tlog" in _tree(folder)
    execute.trim(folder, "summary")
    assert set(_tree(folder)) == {"summary.json", "scenario.yaml"}


def test_the_inclusion_rate_pools_every_support_in_a_zone():
    summary = {
        "diagnostics": {
            "supports": {
                "support-1": {"zone_cycles": 10, "fused_in_zone": 1},
                "support-2": {"zone_cycles": 30, "fused_in_zone": 9},
                "support-3": {"zone_cycles": 0, "fused_in_zone": 0},
            }
        }
    }
    assert inclusion_rate(summary) == 0.25
    assert inclusion_rate({"diagnostics": {"supports": {}}}) is None


def _tree(root: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()
    }


def test_without_ray_the_ray_engine_says_in_one_line_how_to_install_it(
    tmp_path, monkeypatch, capsys
):
    import sys

    import mission.cli

    monkeypatch.setitem(sys.modules, "ray", None)  # `import ray` fails as if not installed
    monkeypatch.chdir(tmp_path)
    study = tmp_path / "s.yaml"
    study.write_text("scenarios: [along]\nseeds: 1\n")
    status = mission.cli.entry_point(["study", str(study), "--engine", "ray"])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "pip install -e '.[ray]'" in err[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.yaml"]


def test_a_report_written_again_from_results_csv_is_the_report_the_study_wrote(tmp_path):
    """``mission study --report-only``: from results.csv alone, the same report.md, Table 3
    and figures, byte for byte; nothing runs."""
    import mission.cli

    spec = StudySpec(
        "t", "A test.", Path("t.yaml"), ("along",), ("ac", "nac"), (0, 1, 2),
        (Point((("map.eta", 0.3),)), Point((("map.eta", 0.6),))), ("table3",),
    )  # fmt: skip
    run_study(spec, tmp_path, FakeEngine(), progress=io.StringIO())

    def reports() -> dict[str, bytes]:
        return {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.suffix in (".md", ".csv")}

    written = reports()
    for name in written:
        if name != "results.csv":
            (tmp_path / name).unlink()
    rewrite_report(spec, tmp_path)
    again = reports()
    assert again == written and "report.md" in again and "table.md" in again
    study_file = tmp_path / "t.yaml"
    study_file.write_text("name: t\nscenarios: [along]\nmethods: [ac]\nseeds: [0]\n")
    empty = tmp_path / "empty"
    empty.mkdir()
    argv = ["study", str(study_file), "--out", str(empty), "--report-only"]
    assert mission.cli.entry_point(argv) == 2  # no results.csv: nothing to report on


def test_runs_whose_g_the_study_drops_write_none(tmp_path, monkeypatch):
    started = []
    monkeypatch.setattr(execute.subprocess, "Popen", lambda argv, **_: started.append(argv))
    run = StudyRun("along", "along", 0, {}, "ac", 3, "k" * 16)
    for keep in ("all", "logs", "summary"):
        execute.start(run, tmp_path, mpc_helper=False, keep=keep)
    lean = [
        argv[argv.index("--g-snapshots") + 1] if "--g-snapshots" in argv else None
        for argv in started
    ]
    assert lean == [None, "none", "none"]  # keep all: every snapshot, as a plain run


def test_a_geometry_study_reports_gnss_errors_and_pairs_the_steps_over_the_mdb(tmp_path):
    """Runs whose multipath came from geometry: the report's means carry the supports' GNSS
    errors, and AC against NAC pairs the fixes off by more than the MDB (here AC's are 5 and
    NAC's 25 in every pair: -20) instead of the zones' steps."""
    from mission.studies.report import write_report

    spec = _spec(seeds=(0, 1, 2, 3, 4))
    rows = []
    for seed in spec.seeds:
        for method, off in (("ac", 5), ("nac", 25)):
            row = {**_summary(StudyRun("along", "along", 0, {}, method, seed, "k"))}
            row.update(
                {
                    "scenario": "along",
                    "point": 0,
                    "gnss_multipath": "geometry",
                    "gnss_error_steps_total": off,
                    "supports_gnss_error_m.p95": 2.0,
                    "completion_time_s": row["completion_time_s"],
                    "work_error_m.mean": 0.1,
                }
            )
            rows.append(row)
    write_report(tmp_path, spec, rows, 0)
    report = (tmp_path / "report.md").read_text()
    assert "supports' GNSS error, p95 [m]" in report
    assert "supports' fixes off by more than the MDB: AC - NAC" in report
    assert "| -20.0 (-80.0 %) [-20.0, -20.0]" in report
    assert "steps in multipath: AC - NAC" not in report
