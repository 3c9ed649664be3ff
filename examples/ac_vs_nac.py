"""AC against NAC: the work UAV's error over time in the two methods, the same seed, plotted
your own way from the runs' data frames.

    python examples/ac_vs_nac.py [--out DIR] [--seed S]
"""

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from mission import run

parser = argparse.ArgumentParser()
parser.add_argument("--out", default="example-output/ac-vs-nac")
parser.add_argument("--quick", action="store_true", help="cut every run at 40 s (a test)")
parser.add_argument("--seed", type=int, default=0)
args = parser.parse_args()
out = Path(args.out)

fig, ax = plt.subplots(figsize=(8, 4))
for method in ("ac", "nac"):
    cut = {"run.timeout_s": 40.0} if args.quick else None
    r = run("along", method=method, seed=args.seed, overrides=cut, out=out / method, force=True)
    estimates = r.estimates()
    work = estimates[estimates["vehicle"] == "work"].set_index("t")[["e", "n", "u"]]
    truth = r.truth()
    true = truth[truth["vehicle"] == "work"].set_index("t")[["e", "n", "u"]]
    joined = work.join(true.add_suffix("_true"), how="inner")
    estimated = joined[["e", "n", "u"]].to_numpy()
    error = np.linalg.norm(estimated - joined[["e_true", "n_true", "u_true"]].to_numpy(), axis=1)
    steps = r.summary.multipath_steps_total
    ax.plot(joined.index, error, label=f"{method.upper()}: {steps} steps in multipath")
    print(f"{method}: completed at {r.summary.completion_time_s} s, error {error.mean():.3f} m")
ax.set_xlabel("simulated time [s]")
ax.set_ylabel("work UAV error [m]")
ax.set_title(f"Along, seed {args.seed}: the work UAV's error, AC against NAC")
ax.legend()
fig.tight_layout()
fig.savefig(out / "error.png", dpi=100)
print(f"wrote {out / 'error.png'}")
