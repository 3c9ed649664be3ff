"""What a run's caller chooses besides the scenario, named once for every command line and the
Python API: the scenario run when none is named, and which snapshots of G a run writes."""

from __future__ import annotations

from typing import Literal, get_args

DEFAULT_SCENARIO = "along"  # what ``mission run``, the processes and ``mission.run`` fly

# ``every``: the start, every SNAPSHOT_EVERY cycles and the end (what the 3-D view replays);
# ``ends``: the start and the end (what G learned); ``none``
GSnapshots = Literal["every", "ends", "none"]
G_SNAPSHOTS: tuple[GSnapshots, ...] = get_args(GSnapshots)
