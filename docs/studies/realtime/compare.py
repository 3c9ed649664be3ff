"""Real time against lockstep, seed by seed: the table in docs/reproduction.md.

python docs/studies/realtime/compare.py REALTIME/results.csv LOCKSTEP/results.csv
"""

import csv
import sys

import numpy as np

METRICS = (
    ("completion_time_s", "completion [s]", "{:.1f}"),
    ("multipath_steps_total", "steps in multipath", "{:.1f}"),
    ("work_error_m.mean", "mean error [m]", "{:.3f}"),
)


def rows(path):
    with open(path, newline="") as handle:
        return {(r["scenario"], r["method"], int(r["seed"])): r for r in csv.DictReader(handle)}


def main(realtime_csv, lockstep_csv):
    realtime, lockstep = rows(realtime_csv), rows(lockstep_csv)
    print(
        "| scenario | method | metric | real time x10 | lockstep | real time - lockstep (paired) |"
    )
    print("|---|---|---|---|---|---|")
    for scenario, method in sorted({(s, m) for s, m, _ in realtime}):
        seeds = sorted(k[2] for k in realtime if k[:2] == (scenario, method))
        for key, label, number in METRICS:
            a = np.array([float(realtime[(scenario, method, s)][key]) for s in seeds])
            b = np.array([float(lockstep[(scenario, method, s)][key]) for s in seeds])
            d = a - b
            cells = [
                f"{number.format(x.mean())} +/- {number.format(x.std(ddof=1))}" for x in (a, b, d)
            ]
            print(f"| {scenario} | {method.upper()} | {label} | " + " | ".join(cells) + " |")
    ages = np.array(
        [
            [float(r[f"measurement_age_ms.{q}"]) for q in ("median", "p95", "max")]
            for r in realtime.values()
        ]
    )
    print(
        f"\nmeasurement ages over the {len(ages)} real-time runs [ms]: median of medians "
        f"{np.median(ages[:, 0]):.0f}, p95 {np.median(ages[:, 1]):.0f} (median over runs), "
        f"largest {ages[:, 2].max():.0f}"
    )


if __name__ == "__main__":
    main(*sys.argv[1:3])
