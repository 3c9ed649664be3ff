"""A sweep from Python: the map's update rate eta at two values, AC and NAC, two seeds, runs
cut at 60 s (with --quick: AC alone, one seed, cut at 40 s); the results as a data frame.

    python examples/sweep.py [--out DIR]
"""

import argparse

from mission import study

parser = argparse.ArgumentParser()
parser.add_argument("--out", default="example-output/sweep")
parser.add_argument("--quick", action="store_true", help="cut every run at 40 s (a test)")
args = parser.parse_args()

s = study(
    {
        "name": "eta-sweep",
        "scenarios": ["along"],
        "methods": ["ac"] if args.quick else ["ac", "nac"],
        "seeds": 1 if args.quick else 2,
        "points": [
            {"map.eta": 0.3, "run.timeout_s": 40.0 if args.quick else 60.0},
            {"map.eta": 0.6, "run.timeout_s": 40.0 if args.quick else 60.0},
        ],
    },
    out=args.out,
    keep="summary",
)
table = s.results.groupby(["map.eta", "method"])[["multipath_steps_total", "work_error_m.mean"]]
print(table.mean().round(3))
print(f"report: {s.report}")
