"""Where a study's numbers came from, and whether today's code gives them again: the canary
first, provenance.json and the report's footer, a study marked historical, and --verify's
draw, comparison and verdict (a stand-in engine makes the runs; tests/studies/
test_verify_runs.py verifies committed studies with real runs)."""

from __future__ import annotations

import csv
import hashlib
import io
import json
import subprocess
from importlib import metadata

import pytest

from mission.config.errors import InputError
from mission.studies.canary import CANARY
from mission.studies.provenance_file import mark_historical, read_provenance
from mission.studies.runkeys import code_version
from mission.studies.study import rewrite_report, run_study
from mission.studies.verify import draw, run_verify
from tests.processes import ROOT
from tests.studies.test_study import FakeEngine, _spec


@pytest.fixture
def made(tmp_path):
    """A study made with its canary by the stand-in engine: (its folder, the engine)."""
    engine = FakeEngine()
    run_study(_spec(), tmp_path / "study", engine, progress=io.StringIO(), canary=True)
    return tmp_path / "study", engine


def test_the_canary_runs_first_and_its_digest_is_the_provenances(made):
    study, engine = made
    assert [folder.split("-ac-")[0] for folder in engine.ran[:4]] == [
        "canary-along-0",
        "canary-piers-1",
        "canary-along-2",
        "canary-piers-3",
    ]
    assert not any(folder.startswith("canary") for folder in engine.ran[4:])
    provenance = read_provenance(study)
    digests = [f"canary-{c.scenario}-{n}-{n}-ac-0" for n, c in enumerate(CANARY)]
    expected = hashlib.sha256(json.dumps(digests).encode()).hexdigest()[:16]
    assert provenance["canary"]["digest"] == expected
    assert [r["decisions_digest"] for r in provenance["canary"]["runs"]] == digests
    rows = list(csv.DictReader((study / "results.csv").open()))
    assert len(rows) == 12 and not any(r["scenario"].startswith("canary") for r in rows)


def test_provenance_names_the_commit_the_packages_and_the_code(made):
    study, _ = made
    provenance = read_provenance(study)
    head = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True)
    assert provenance["commit"] == head.stdout.strip()
    assert isinstance(provenance["dirty"], bool)
    assert provenance["version"] == metadata.version("bridge-uav-formation")
    assert provenance["code_version"] == code_version()
    for name in ("casadi", "numpy", "scipy", "pymavlink"):
        assert provenance["packages"][name] == metadata.version(name)
    assert provenance["machine"]["numerics"]["numpy_simd"]
    assert provenance["historical"] is None
    report = (study / "report.md").read_text()
    assert "## Provenance" in report and provenance["commit"][:12] in report
    assert f"Canary `{provenance['canary']['digest']}`" in report


def test_a_rerun_and_a_rewritten_report_keep_the_footer_byte_for_byte(made):
    study, _ = made
    before = (study / "report.md").read_bytes()
    engine = FakeEngine()
    run_study(_spec(), study, engine, progress=io.StringIO(), canary=True)
    assert engine.ran == [] and (study / "report.md").read_bytes() == before
    rewrite_report(_spec(), study)
    assert (study / "report.md").read_bytes() == before


def test_a_study_marked_historical_says_so_first(made):
    study, _ = made
    mark_historical(study, "made before the margins")
    rewrite_report(_spec(), study)
    first = (study / "report.md").read_text().splitlines()[0]
    commit = read_provenance(study)["commit"][:12]
    assert first.startswith("> **Historical**") and commit in first
    assert "made before the margins" in first


def test_a_study_without_provenance_is_marked_with_an_unknown_commit(tmp_path):
    (tmp_path / "results.csv").write_text("scenario,point,method,seed\n")
    mark_historical(tmp_path, "older than provenance")
    assert read_provenance(tmp_path) == {
        "study": tmp_path.name,
        "commit": None,  # not in a git checkout
        "committed_with": True,
        "historical": "older than provenance",
    }


def test_a_committed_study_without_provenance_names_the_commit_that_committed_it(tmp_path):
    folder = ROOT / "docs" / "studies" / "table3"
    log = subprocess.run(
        ["git", "log", "-1", "--follow", "--format=%H", "--", "results.csv"],
        cwd=folder,
        capture_output=True,
        text=True,
    )
    from mission.procs.provenance import last_commit_of

    assert last_commit_of(folder / "results.csv") == log.stdout.strip()


def test_a_broken_provenance_file_is_bad_input_naming_it(tmp_path):
    (tmp_path / "provenance.json").write_text("{not json")
    with pytest.raises(InputError, match=r"provenance\.json"):
        read_provenance(tmp_path)


def test_the_draw_is_seeded_in_study_order_and_all_when_asked_for_more():
    rows = [(n, {}) for n in range(60)]
    chosen = draw(rows, 5)
    assert chosen == draw(rows, 5) and [n for n, _ in chosen] == sorted(n for n, _ in chosen)
    assert chosen != draw(rows, 5, seed=1)
    assert draw(rows, None) == rows and draw(rows, 99) == rows


def _verify(study, tmp_path, count=None):
    progress = io.StringIO()
    out = run_verify(_spec(), study, count, tmp_path / "verify", FakeEngine(), progress=progress)
    return out, progress.getvalue()


def test_a_study_verifies_against_itself_with_its_canary(made, tmp_path):
    study, _ = made
    outcome, progress = _verify(study, tmp_path, count=3)
    assert outcome.agrees, outcome.lines
    assert "as when the study was made" in progress.splitlines()[1]  # said before the rows
    assert "3 of 3 rows compared: 0 differ" in "\n".join(outcome.lines)
    assert (tmp_path / "verify" / "verify.md").read_text().splitlines() == outcome.lines


def test_a_changed_cell_is_listed_and_fails_but_a_timing_is_not_compared(made, tmp_path):
    study, _ = made
    rows = list(csv.DictReader((study / "results.csv").open()))
    rows[1]["multipath_steps_total"] = "999"
    rows[2]["wall_time_s"] = "123.4"
    for row in rows:
        row["roles.waypoints_reached.support-9.of"] = ""  # a metric no run today has: empty
    columns = [c for c in rows[0] if c != "decisions_digest"]  # as if added since: not compared
    with (study / "results.csv").open("w") as out:
        writer = csv.DictWriter(out, fieldnames=columns, lineterminator="\n", extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)
    outcome, _ = _verify(study, tmp_path)
    assert not outcome.agrees
    table = [line for line in outcome.lines if line.startswith("| along")]
    assert table == ["| along NAC seed 0 | multipath_steps_total | 999 | 40 |"]
    # (an empty committed cell of a column today's row lacks is the same nothing)
    assert "columns only today's code writes (not compared): decisions_digest" in outcome.lines


def test_a_stale_canary_is_said_at_once_with_the_commit(made, tmp_path):
    study, _ = made
    provenance = read_provenance(study)
    runs = provenance["canary"]["runs"]
    runs[2]["decisions_digest"] = "0" * 16  # the integrity run (the study flies no quadrotors)
    (study / "provenance.json").write_text(json.dumps(provenance))
    outcome, progress = _verify(study, tmp_path, count=1)
    assert not outcome.agrees
    said = progress.splitlines()[1]
    assert said.startswith("canary: STALE") and provenance["commit"][:12] in said
    assert runs[2]["run"] in said and runs[0]["run"] not in said and runs[1]["run"] not in said


def test_a_study_made_before_a_canary_run_joined_is_compared_on_the_runs_it_has(made, tmp_path):
    study, _ = made
    provenance = read_provenance(study)
    provenance["canary"]["runs"] = provenance["canary"]["runs"][:2]  # an older canary
    provenance["canary"]["digest"] = "older"
    (study / "provenance.json").write_text(json.dumps(provenance))
    outcome, progress = _verify(study, tmp_path, count=1)
    assert outcome.agrees and "as when the study was made" in progress.splitlines()[1]


def test_a_canary_run_that_flies_quadrotors_speaks_only_for_studies_that_fly_them():
    from pathlib import Path

    from mission.studies.canary import canary_differences, flies_quadrotors
    from mission.studies.spec import load_study, shipped_study

    labels = [c.label for c in CANARY]
    then = {"runs": [{"run": label, "decisions_digest": "a"} for label in labels]}
    today = {"runs": [{"run": label, "decisions_digest": "a"} for label in labels]}
    today["runs"][1]["decisions_digest"] = "b"  # the piers run, with quadrotors, moved
    assert "multicopter" in labels[1]
    assert canary_differences(then, today) == [labels[1]]
    assert canary_differences(then, today, quadrotors=False) == []
    assert flies_quadrotors(load_study(shipped_study(Path("dynamics"))))
    assert not flies_quadrotors(load_study(shipped_study(Path("table3"))))
