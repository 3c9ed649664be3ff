"""A run's key: what determines its results, and nothing else."""

from __future__ import annotations

import shutil
from pathlib import Path

from mission.config.scenario import embedded_scenarios_dir
from mission.studies.runkeys import code_version, resolved_key, study_runs
from mission.studies.spec import Point, StudySpec


def _spec(points: tuple[Point, ...] | None = None) -> StudySpec:
    points = points or (Point(()),)
    return StudySpec("s", "", Path("s.yaml"), ("along",), ("ac", "nac"), (0, 1), points, ())


def test_keys_differ_by_method_seed_and_override_and_not_by_a_default_restated():
    points = (Point(()), Point((("fusion.rho_threshold", 0.5),)), Point((("map.eta", 0.3),)))
    runs = study_runs(_spec(points=points), {"along": "along"}, "code")
    keys = {(r.point, r.method, r.seed): r.key for r in runs}
    assert len(set(keys.values())) == 8  # points 0 and 2 are the same scenario
    assert all(keys[(0, m, s)] == keys[(2, m, s)] for m in ("ac", "nac") for s in (0, 1))
    assert runs[0].folder == f"along-ac-0-{runs[0].key[:10]}"
    other_code = study_runs(_spec(), {"along": "along"}, "changed")
    assert other_code[0].key != runs[0].key


def test_a_realtime_run_has_a_key_of_its_own_and_is_started_in_real_time(tmp_path):
    from dataclasses import replace
    from unittest import mock

    from mission.studies import execute

    lockstep = study_runs(_spec(), {"along": "along"}, "code")
    realtime = study_runs(replace(_spec(), speedup=10.0), {"along": "along"}, "code")
    assert {r.key for r in lockstep}.isdisjoint(r.key for r in realtime)
    assert realtime[0].speedup == 10.0 and lockstep[0].speedup is None
    with mock.patch.object(execute.subprocess, "Popen") as popen:
        execute.start(realtime[0], tmp_path, mpc_helper=True)
        execute.start(lockstep[0], tmp_path, mpc_helper=True)
    realtime_command, lockstep_command = (c.args[0] for c in popen.call_args_list)
    assert realtime_command[-3:] == ["--realtime", "--speedup", "10.0"]
    assert "--realtime" not in lockstep_command


def test_a_key_follows_the_contents_of_the_plan_files_not_their_path(tmp_path):
    plans = embedded_scenarios_dir() / "plans" / "bridge"
    for name in ("a", "b"):
        shutil.copytree(plans, tmp_path / name / "plans")
        (tmp_path / name / "s.yaml").write_text("extends: along\ntask: {waypoints_dir: plans}\n")
    a, b = (str(tmp_path / n / "s.yaml") for n in "ab")
    assert resolved_key(a, Point(())) == resolved_key(b, Point(()))
    work = tmp_path / "b" / "plans" / "work.waypoints"
    work.write_text(work.read_text().replace("7.0", "7.5", 1) + "\n")
    assert resolved_key(a, Point(())) != resolved_key(b, Point(()))
    assert resolved_key(a, Point(())) == resolved_key("along", Point(()))


def test_the_code_version_follows_the_code_a_run_executes(tmp_path, monkeypatch):
    """A byte changed in a module a run executes changes the digest; a file it does not
    read (a note, a cache) does not."""
    import shutil
    from importlib import resources

    import mission.studies.runkeys as runkeys

    copy = tmp_path / "ground_station"
    shutil.copytree(Path(str(resources.files("ground_station"))), copy)
    real = resources.files

    def files(package: str):
        return copy if package == "ground_station" else real(package)

    monkeypatch.setattr(runkeys.resources, "files", files)
    before = code_version()
    assert len(before) == 64 and before == code_version()
    (copy / "NOTES.md").write_text("not code")
    (copy / "__pycache__" / "x.pyc").parent.mkdir(exist_ok=True)
    (copy / "__pycache__" / "x.pyc").write_bytes(b"cache")
    assert code_version() == before
    fusion = copy / "estimation" / "fusion.py"
    fusion.write_text(fusion.read_text() + "\n# a comment is code too: the digest is of bytes\n")
    assert code_version() != before
