"""G over time: each snapshot of the map (``g/G_*.npy``) as the voxels where it differs from
its initial value, at the time of the cycle it was taken after."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mission.viewer import frame as f
from mission.viewer.tail import SnapshotTail


class MapRows:
    """Voxel rows from G's snapshots; ``initial`` is sigma_0, used until G_initial is read."""

    def __init__(self, g_dir: Path, initial: np.ndarray) -> None:
        self.initial = initial
        self.tail = SnapshotTail(g_dir, initial.shape)

    def read(self, cycle_times: list[float], final: bool) -> list[f.VoxelRow]:
        rows = []
        for label, values in self.tail.read(len(cycle_times), final):
            if label == "initial":
                self.initial = values
                time_s = 0.0
            elif label == "final":
                time_s = cycle_times[-1] if cycle_times else 0.0
            else:
                time_s = cycle_times[int(label) - 1]
            changed = np.abs(values - self.initial) > f.G_CHANGED_M
            rows.append(f.VoxelRow(time_s, np.argwhere(changed), values[changed]))
        return rows
