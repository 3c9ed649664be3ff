"""What the repository publishes is what the committed studies hold: every study under
docs/studies has its provenance (or says it is historical and why), and the README's tables
and its first run are the committed Table 3's numbers."""

from __future__ import annotations

import re
import statistics

import pytest

from mission.studies.provenance_file import read_provenance
from mission.studies.results import read_results_csv
from mission.studies.stats import wilcoxon_p
from tests.processes import ROOT

COMMITTED = ROOT / "docs" / "studies"
STUDIES = sorted(p for p in COMMITTED.iterdir() if p.is_dir())


@pytest.mark.parametrize("folder", STUDIES, ids=[p.name for p in STUDIES])
def test_every_committed_study_says_where_its_numbers_came_from(folder):
    provenance = read_provenance(folder)
    assert provenance is not None, f"{folder.name} has no provenance.json"
    if provenance.get("historical"):
        assert len(provenance["historical"]) > 10  # says why
        return
    assert re.fullmatch(r"[0-9a-f]{40}", provenance["commit"]), provenance["commit"]
    assert provenance["dirty"] is False, "made from a tree with uncommitted changes"
    assert re.fullmatch(r"[0-9a-f]{16}", provenance["canary"]["digest"])
    assert provenance["machine"]["numerics"]["pinned"], "made with unpinned kernels"
    report = folder / "report.md"
    if report.is_file():
        assert provenance["commit"][:12] in report.read_text().split("## Provenance")[-1]


def _rows(study: str) -> list[dict]:
    return read_results_csv((COMMITTED / study / "results.csv").read_text(encoding="utf-8"))


def _p(value: float) -> str:
    """A p-value as the README writes it: two significant digits, 6.1e-5 or 0.022."""
    return re.sub(r"e-0*(\d)", r"e-\1", f"{value:.2g}")


def _comparison(rows: list[dict], column: str, unit: str) -> str:
    """``AC mean vs NAC mean[ unit]: change % (p = p)`` over the seeds both have (completion
    time: both completed)."""
    by_method: dict[str, dict[int, float]] = {"ac": {}, "nac": {}}
    for row in rows:
        if column == "completion_time_s" and not row["completed"]:
            continue
        by_method[row["method"]][row["seed"]] = float(row[column])
    seeds = sorted(by_method["ac"].keys() & by_method["nac"].keys())
    ac = [by_method["ac"][s] for s in seeds]
    nac = [by_method["nac"][s] for s in seeds]
    mean_ac, mean_nac = statistics.fmean(ac), statistics.fmean(nac)
    change = 100 * (mean_ac - mean_nac) / mean_nac
    return f"{mean_ac:.1f} vs {mean_nac:.1f}{unit}: {change:+.1f} % (p = {_p(wilcoxon_p(ac, nac))})"


@pytest.mark.parametrize("study", ["table3-paper", "table3"])
def test_the_readmes_tables_are_the_committed_table3(study):
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    rows = _rows(study)
    for scenario in ("along", "wall"):
        mine = [r for r in rows if r["scenario"] == scenario]
        steps = _comparison(mine, "multipath_steps_total", "")
        time_s = _comparison(mine, "completion_time_s", " s")
        line = f"| {scenario.capitalize()} | {steps} | {time_s} |"
        assert line in readme, f"README.md lacks {study}'s row, which the results give as {line}"


def test_the_readmes_first_run_is_the_committed_table3s_along_ac_seed_0():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    row = next(
        r
        for r in _rows("table3")
        if (r["scenario"], r["method"], r["seed"], r["point"]) == ("along", "ac", 0, 0)
    )
    supports = ", ".join(f"support-{n} {row[f'multipath_steps.support-{n}']}" for n in (1, 2, 3))
    said = (
        f"completed at {row['completion_time_s']:.1f} s; {row['control_cycles']} cycles; "
        f"steps in multipath {row['multipath_steps_total']} ({supports}); work UAV error mean "
        f"{row['work_error_m.mean']:.4f} m"
    )
    assert said in readme
