"""What a study whose multipath comes from geometry says beyond its report, from
its kept runs::

    python -m mission.studies.geometry_report river STUDY_OUT [--figure F.png]

- **Does G learn the right places?** Per scenario, point and method, the mean over runs of
  G's and the prior's agreement with the true error field on the voxels the run taught
  (:mod:`mission.analysis.map_truth`);
- **the supports' errors** along their paths: percentiles of every fix's true error, pooled
  over the runs, and (``--figure``) their distribution beside the published magnitudes.

``STUDY_OUT`` is the study's ``--out`` folder with its run folders (``--keep logs``).
"""

from __future__ import annotations

import argparse
import csv
from collections import defaultdict
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from mission.studies.spec import load_study

# published magnitudes near bridges (docs/model.md): (what, low, high) in metres
PUBLISHED_M = (
    ("a ground or water bounce under a deck (excess path)", 1.5, 13.0),
    ("off piers at 2-10 m (excess path)", 4.0, 19.0),
    ("position, one-sided sky under a deck", 5.0, 30.0),
)
PERCENTILES = (50, 90, 95, 99, 100)


def _runs(study_file: Path, out: Path):
    """(scenario, point, method, run folder) of each finished run of the study."""
    load_study(study_file)  # the study file must be valid
    for row in csv.DictReader((out / "results.csv").open()):
        name = f"{row['scenario']}-{row['method']}-{row['seed']}-{row['run_key'][:10]}"
        yield row["scenario"], int(row["point"]), row["method"], out / "runs" / name


def map_table(study_file: Path, out: Path) -> str:
    """Markdown: G's and the prior's Spearman and top-decile precision/recall against the
    true error field, the mean over each group's runs."""
    from mission.analysis.map_truth import run_map_against_truth, run_world

    spec = load_study(study_file)
    found: dict[tuple[str, int, str], list[dict]] = defaultdict(list)
    worlds: dict[tuple[str, int], object] = {}  # a point's runs share its world
    for scenario, point, method, folder in _runs(study_file, out):
        if not (folder / "scenario.yaml").is_file():
            continue
        if (scenario, point) not in worlds:
            worlds[(scenario, point)] = run_world(folder)
        result = run_map_against_truth(folder, worlds[(scenario, point)])
        if result is not None:
            found[(scenario, point, method)].append(result)
    lines = [
        "| scenario | point | method | runs | voxels learned | Spearman G / prior | "
        "top decile precision G / prior | recall G / prior |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for (scenario, point, method), results in sorted(found.items()):
        cells = [f"{np.mean([r['learned_voxels'] for r in results]):.0f}"]
        for field in ("spearman", "precision", "recall"):
            cells.append(f"{_mean(results, 'G', field)} / {_mean(results, 'prior', field)}")
        lines.append(
            f"| {scenario} | {spec.points[point].label} | {method.upper()} | {len(results)} | "
            + " | ".join(cells)
            + " |"
        )
    return "\n".join(lines)


def _mean(results: list[dict], which: str, field: str) -> str:
    values = [r[which][field] for r in results if r[which][field] is not None]
    return f"{np.mean(values):.2f}" if values else "-"


def support_errors(study_file: Path, out: Path) -> dict[tuple[str, int], np.ndarray]:
    """Every support fix's true error, pooled per scenario and point (both methods)."""
    from mission.analysis.gnss_errors import support_fix_errors
    from mission.analysis.metrics import read_tlog
    from mission.config.scenario import load_scenario

    pooled: dict[tuple[str, int], list[np.ndarray]] = defaultdict(list)
    for scenario, point, _, folder in _runs(study_file, out):
        tlog, scenario_file = folder / "gcs.tlog", folder / "scenario.yaml"
        if tlog.is_file() and scenario_file.is_file():
            trace = read_tlog(tlog, load_scenario(str(scenario_file)))
            pooled[(scenario, point)] += list(support_fix_errors(trace).values())
    return {key: np.concatenate(parts) for key, parts in pooled.items() if parts}


def error_table(study_file: Path, errors: dict[tuple[str, int], np.ndarray]) -> str:
    """Markdown: percentiles of the supports' errors per scenario and point."""
    spec = load_study(study_file)
    header = " | ".join("max" if p == 100 else f"p{p}" for p in PERCENTILES)
    lines = [f"| scenario | point | fixes | {header} |", "|" + "---|" * (3 + len(PERCENTILES))]
    for (scenario, point), values in sorted(errors.items()):
        cells = " | ".join(f"{np.percentile(values, p):.2f}" for p in PERCENTILES)
        lines.append(f"| {scenario} | {spec.points[point].label} | {len(values)} | {cells} |")
    return "\n".join(lines)


def error_figure(study_file: Path, errors: dict[tuple[str, int], np.ndarray], path: Path) -> None:
    """The distribution of the supports' errors (log axes) beside the published ranges."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from mission.analysis.figures import save_figure

    spec = load_study(study_file)
    fig, ax = plt.subplots(figsize=(9, 4.8))
    bins = np.logspace(-2, 2, 61)
    for (scenario, point), values in sorted(errors.items()):
        label = f"{scenario}, {spec.points[point].label} ({len(values)} fixes)"
        ax.hist(np.maximum(values, bins[0]), bins=bins, histtype="step", linewidth=1.6, label=label)
    top = ax.get_ylim()[1]
    for row, (what, low, high) in enumerate(PUBLISHED_M):
        y = top * (1.08 + 0.09 * row)
        ax.plot([low, high], [y, y], linewidth=4, alpha=0.6, label=f"published: {what}")
    ax.set_xscale("log")
    ax.set_ylim(0, top * (1.1 + 0.09 * len(PUBLISHED_M)))
    ax.set_xlabel("a support's true GNSS error |fix - truth| [m]")
    ax.set_ylabel("fixes")
    ax.set_title("supports' GNSS errors along their paths, and published magnitudes near bridges")
    ax.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)


def main(argv: Sequence[str] | None = None) -> int:
    """Print the two tables (and draw the figure)."""
    parser = argparse.ArgumentParser(prog="python -m mission.studies.geometry_report")
    parser.add_argument("study", type=Path, help="the study file")
    parser.add_argument("out", type=Path, help="the study's --out folder (with runs/)")
    parser.add_argument("--figure", type=Path, help="draw the errors' distribution here")
    args = parser.parse_args(argv)
    print(map_table(args.study, args.out))
    print()
    errors = support_errors(args.study, args.out)
    print(error_table(args.study, errors))
    if args.figure is not None:
        error_figure(args.study, errors, args.figure)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
