"""What G learned in each run of a study (:mod:`mission.analysis.map_learning`), as a table
per scenario, point and method::

    python -m mission.studies.map_learning faults STUDY_OUT

where ``STUDY_OUT`` is the study's ``--out`` folder with its run folders (``runs/``; the
committed ``docs/studies/*`` hold no run folders).
"""

from __future__ import annotations

import argparse
import csv
from collections import defaultdict
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from mission.analysis.map_learning import RAISED_M, run_raised_voxels
from mission.studies.spec import load_study


def study_table(study_file: Path, out: Path) -> str:
    """Markdown: the mean of :func:`run_raised_voxels` per scenario, point and method over the
    runs of ``study_file`` written to ``out``."""
    spec = load_study(study_file)
    counts: dict[tuple[str, int, str], list[dict]] = defaultdict(list)
    for row in csv.DictReader((out / "results.csv").open()):
        name = f"{row['scenario']}-{row['method']}-{row['seed']}-{row['run_key'][:10]}"
        found = run_raised_voxels(out / "runs" / name)
        if found is not None:
            counts[(row["scenario"], int(row["point"]), row["method"])].append(found)
    lines = [
        f"| scenario | point | method | runs | G raised > {RAISED_M} m near a zone | elsewhere |",
        "|---|---|---|---|---|---|",
    ]
    for (scenario, point, method), found in sorted(counts.items()):
        near = np.mean([f["near_zone"] for f in found])
        elsewhere = np.mean([f["elsewhere"] for f in found])
        label = spec.points[point].label
        lines.append(
            f"| {scenario} | {label} | {method.upper()} | {len(found)} | {near:.1f} | "
            f"{elsewhere:.1f} |"
        )
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    """Print :func:`study_table`."""
    parser = argparse.ArgumentParser(prog="python -m mission.studies.map_learning")
    parser.add_argument("study", type=Path, help="the study file")
    parser.add_argument("out", type=Path, help="the study's --out folder (with runs/)")
    args = parser.parse_args(argv)
    print(study_table(args.study, args.out))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
