"""Every number we publish reproduces: today's canary against each committed study's, and
two rows of Table 3 (our defaults and the paper's form) made again and compared."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from mission.studies.canary import (
    canary_differences,
    canary_record,
    canary_runs,
    flies_quadrotors,
)
from mission.studies.local_engine import LocalEngine
from mission.studies.provenance_file import read_provenance
from mission.studies.results import read_results_csv
from mission.studies.runkeys import code_version
from mission.studies.spec import load_study, shipped_study
from tests.processes import ROOT, mission

pytestmark = pytest.mark.slow  # every test here starts runs

COMMITTED = ROOT / "docs" / "studies"


@pytest.fixture(scope="module")
def canary(tmp_path_factory) -> tuple[Path, dict]:
    """Today's canary, made once: (the runs folder holding it, its record)."""
    runs_dir = tmp_path_factory.mktemp("runs")
    runs = canary_runs(code_version())
    made: dict = {}
    LocalEngine(2).run(runs, runs_dir, "logs", lambda run, summary, _: made.update({run: summary}))
    return runs_dir, canary_record([made.get(run) for run in runs])


@pytest.mark.determinism
def test_every_committed_study_gives_todays_canary_or_is_marked_historical(canary):
    """A commit that changes what the code decides leaves the committed studies stale: it
    re-runs them, or marks them historical (docs/development.md)."""
    _, today = canary
    assert today["digest"], today
    stale = []
    for folder in sorted(p for p in COMMITTED.iterdir() if p.is_dir()):
        provenance = read_provenance(folder)
        if provenance is None or provenance.get("historical"):
            continue  # test_committed: each has one (and historical ones say why)
        spec = shipped_study(Path(folder.name))
        quadrotors = spec is None or flies_quadrotors(load_study(spec))
        differing = canary_differences(provenance.get("canary"), today, quadrotors)
        if differing != []:
            commit = str(provenance.get("commit"))[:12]
            stale.append(f"{folder.name} (made with {commit}: {differing or 'no shared run'})")
    assert not stale, (
        f"today's canary is {today['digest']} ({today['runs']}); these studies were made "
        f"with other decisions: re-run them or mark them historical: {', '.join(stale)}"
    )


@pytest.mark.parametrize("study", ["table3", "table3-paper"])
def test_two_rows_of_table3_are_made_again_as_committed(study, canary, tmp_path):
    runs_dir, _ = canary  # the canary is made once for both
    result = mission(
        "study",
        study,  # a shipped study, by its name
        "--verify",
        "2",
        "--against",
        str(COMMITTED / study),
        "--out",
        str(tmp_path / "verify"),
        "--runs",
        str(runs_dir),
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert "2 of 2 rows compared: 0 differ" in result.stdout
    assert "as when the study was made" in result.stdout


def test_a_run_with_the_mpc_helper_decides_as_the_studys_without(along_run):
    """`mission run along` on two cores shares the support MPCs with a helper process, split
    by their last solve times; the Table 3 study's runs (two at a time) have none. The same
    run either way."""
    summary = json.loads((along_run / "summary.json").read_text())
    committed = read_results_csv((COMMITTED / "table3" / "results.csv").read_text())
    row = next(
        r for r in committed if (r["scenario"], r["method"], r["seed"]) == ("along", "ac", 0)
    )
    assert summary["decisions_digest"] == row["decisions_digest"]
    assert summary["control_cycles"] == row["control_cycles"]
    assert summary["multipath_steps_total"] == row["multipath_steps_total"]
    assert summary["lockstep"]["exact"]
