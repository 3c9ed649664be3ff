"""Does G learn the right places? A run's final map against the true error field
that multipath from geometry makes (the receiver's fix error without noise at each voxel's
centre; a voxel without a fix counts as the worst, one inside the structure not at all).

Compared over the voxels the run taught G something (G moved from sigma_0 by more than
``LEARNED_M``: where the supports flew): the rank correlation (Spearman) of G with the field,
and the top decile's precision and recall (G's highest tenth of those voxels against the
field's). The prior sigma_0 on the same voxels is the baseline: a map that learns moves
closer to the field than the prior it started from.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mission.world.model import World

LEARNED_M = 0.01  # a voxel whose G moved this much from sigma_0 has been learned
TOP_SHARE = 0.1


def error_field(world: World) -> np.ndarray:
    """|fix error| (no noise) at every voxel centre of G's grid, in its shape; +inf where a
    receiver there has no fix, NaN inside the structure (compared nowhere)."""
    grid = world.map_grid()
    centres = grid.centers().reshape(-1, 3)
    solution = world.receiver.solve(centres)
    error = np.linalg.norm(solution.position_error_m, axis=1)
    error = np.where(np.isnan(error), np.inf, error)
    return np.where(world.structure.contains(centres), np.nan, error).reshape(grid.shape)


def map_against_field(initial: np.ndarray, final: np.ndarray, field: np.ndarray) -> dict:
    """G's and the prior's agreement with ``field`` over the learned voxels."""
    from scipy.stats import spearmanr

    learned = (np.abs(final - initial) > LEARNED_M).reshape(-1) & ~np.isnan(field.reshape(-1))
    truth = field.reshape(-1)[learned]
    result: dict = {"learned_voxels": int(learned.sum())}
    finite = truth[np.isfinite(truth)]
    varied = len(finite) >= 2 and np.ptp(finite) > 0
    for name, values in (
        ("G", final.reshape(-1)[learned]),
        ("prior", initial.reshape(-1)[learned]),
    ):
        enough = varied and len(truth) >= 10 and np.ptp(values) > 0
        rho = float(spearmanr(values, truth).statistic) if enough else None
        precision, recall = top_overlap(values, truth) if enough else (None, None)
        result[name] = {
            "spearman": _round(rho),
            "precision": _round(precision),
            "recall": _round(recall),
        }
    return result


def top_overlap(values: np.ndarray, truth: np.ndarray) -> tuple[float, float]:
    """Precision and recall of the top ``TOP_SHARE`` of ``values`` (ties at the cut
    included) against the top ``TOP_SHARE`` of ``truth``."""
    flagged = values >= np.quantile(values, 1 - TOP_SHARE)
    finite = np.where(np.isfinite(truth), truth, np.nanmax(truth[np.isfinite(truth)]) + 1)
    worst = finite >= np.quantile(finite, 1 - TOP_SHARE)
    hits = int((flagged & worst).sum())
    return hits / max(int(flagged.sum()), 1), hits / max(int(worst.sum()), 1)


def run_world(run_dir: Path) -> World:
    """The world of the scenario a study's run ran (``scenario.yaml`` in its folder)."""
    return World.load(str(run_dir / "scenario.yaml"))


def run_map_against_truth(run_dir: Path, world: World | None = None) -> dict | None:
    """:func:`map_against_field` of a run folder (None without G's snapshots or where its
    scenario's multipath does not come from geometry); ``world``: its world, if built."""
    world = world or run_world(run_dir)
    initial, final = (run_dir / "g" / f"G_{label}.npy" for label in ("initial", "final"))
    if world.receiver is None or not (initial.is_file() and final.is_file()):
        return None
    return map_against_field(np.load(initial), np.load(final), error_field(world))


def _round(value: float | None) -> float | None:
    return None if value is None else round(value, 4)
