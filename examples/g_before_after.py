"""The map G before and after a run: where the supports' GNSS proved worse than the sky's
geometry promised (AC learns it; NAC never updates G). Slices at the supports' height.

    python examples/g_before_after.py [--out DIR]
"""

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from mission import run

parser = argparse.ArgumentParser()
parser.add_argument("--out", default="example-output/g")
parser.add_argument("--quick", action="store_true", help="cut every run at 40 s (a test)")
args = parser.parse_args()
out = Path(args.out)

cut = {"run.timeout_s": 40.0} if args.quick else None
r = run("along", seed=0, overrides=cut, out=out / "run", force=True, g_snapshots="ends")
before, after = r.g("initial"), r.g("final")
grid_z = 7  # voxel layer 7-8 m: where the supports fly beside the deck
fig, axes = plt.subplots(1, 3, figsize=(14, 4))
extent = (-25, 25, -20, 20)
for ax, values, title in (
    (axes[0], before[:, :, grid_z], "G before (sigma_0 from the sky)"),
    (axes[1], after[:, :, grid_z], "G after the run"),
    (axes[2], after[:, :, grid_z] - before[:, :, grid_z], "what the run taught G"),
):
    image = ax.imshow(values.T, origin="lower", extent=extent, cmap="viridis")
    fig.colorbar(image, ax=ax, label="metres")
    ax.set_title(title)
    ax.set_xlabel("east [m]")
    ax.set_ylabel("north [m]")
raised = int(((after - before) > 0.3).sum())
fig.suptitle(f"Along AC seed 0: G at 7-8 m ({raised} voxels rose more than 0.3 m)")
fig.tight_layout()
fig.savefig(out / "g.png", dpi=100)
print(f"wrote {out / 'g.png'}")
