"""G against the true error field on hand-made maps, and the study's tables from
hand-made study folders."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from mission.analysis.map_truth import map_against_field, top_overlap
from mission.studies import geometry_report

STUDY = """name: g
description: a test
scenarios: [river]
methods: [ac]
seeds: 1
points:
  - {integrity.enabled: true}
"""


def test_a_map_that_learned_the_field_ranks_as_it_does():
    rng = np.random.default_rng(0)
    field = rng.uniform(1, 20, (10, 10, 4))
    initial = np.full(field.shape, 0.15)
    final = initial.copy()
    final[:5] = 0.15 + field[:5] / 10  # learned where the supports flew, in the field's order
    result = map_against_field(initial, final, field)
    assert result["learned_voxels"] == 200
    assert result["G"] == {"spearman": 1.0, "precision": 1.0, "recall": 1.0}
    assert result["prior"] == {"spearman": None, "precision": None, "recall": None}  # flat
    backwards = initial.copy()
    backwards[:5] = 0.15 + (20 - field[:5]) / 10
    assert map_against_field(initial, backwards, field)["G"]["spearman"] == -1.0


def test_no_fix_counts_as_the_worst_error():
    values = np.arange(20.0)
    truth = np.arange(20.0)
    truth[0] = np.inf  # the lowest G where there is no fix: a miss
    precision, recall = top_overlap(values, truth)
    assert precision == pytest.approx(0.5) and recall == pytest.approx(0.5)


def test_the_study_tables_from_its_run_folders(tmp_path):
    study = tmp_path / "g.yaml"
    study.write_text(STUDY)
    out = tmp_path / "out"
    run = out / "runs" / "river-ac-0-abcdefabcd"
    (run / "g").mkdir(parents=True)
    (run / "scenario.yaml").write_text(yaml.safe_dump({"extends": "river", "name": "river"}))
    shape = (50, 40, 20)
    initial = np.full(shape, 0.15)
    final = initial.copy()
    final[20:30, 25:30, 7] = np.linspace(0.2, 2.0, 50).reshape(10, 5)
    np.save(run / "g" / "G_initial.npy", initial)
    np.save(run / "g" / "G_final.npy", final)
    header = "scenario,point,method,seed,run_key\n"
    (out / "results.csv").write_text(header + "river,0,ac,0,abcdefabcdef\n")
    table = geometry_report.map_table(study, out)
    assert "| river | integrity.enabled=True | AC | 1 | 50 |" in table
    errors = {("river", 0): np.array([0.1, 0.2, 1.5, 30.0])}
    assert "| river | integrity.enabled=True | 4 |" in geometry_report.error_table(study, errors)
    figure = tmp_path / "errors.png"
    geometry_report.error_figure(study, errors, figure)
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert geometry_report.support_errors(study, out) == {}  # no tlog kept: nothing pooled


def test_a_study_without_geometry_has_no_map_rows(tmp_path, monkeypatch):
    study = tmp_path / "g.yaml"
    study.write_text(STUDY.replace("[river]", "[along]"))
    out = tmp_path / "out"
    run = out / "runs" / "along-ac-0-abcdefabcd"
    (run / "g").mkdir(parents=True)
    (run / "scenario.yaml").write_text(yaml.safe_dump({"extends": "along", "name": "along"}))
    (out / "results.csv").write_text(
        "scenario,point,method,seed,run_key\nalong,0,ac,0,abcdefabcdef\n"
    )
    assert geometry_report.map_table(study, out).count("\n") == 1  # the header alone


def test_voxels_inside_the_structure_are_not_compared_and_no_fix_anywhere_is_no_answer():
    field = np.arange(60.0).reshape(3, 4, 5)
    initial = np.zeros(field.shape)
    final = field / 100 + 0.5
    inside = field.copy()
    inside[0] = np.nan  # a slab inside the structure
    result = map_against_field(initial, final, inside)
    assert result["learned_voxels"] == 40
    assert result["G"]["spearman"] == 1.0
    blind = map_against_field(initial, final, np.full(field.shape, np.inf))
    assert blind["G"] == {"spearman": None, "precision": None, "recall": None}
