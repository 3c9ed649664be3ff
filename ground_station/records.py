"""What a ground station writes besides its tlog: ``records.jsonl`` (one line per control
cycle), ``g/G_*.npy`` (snapshots of the map G) and ``link.json`` (what the links lost and how
the lockstep recovered)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from ground_station.control.cycle import CycleOutput
from ground_station.estimation.gnss_map import LocalizabilityMap
from ground_station.state.station_state import StationState
from mission.config.run_outputs import G_SNAPSHOTS, GSnapshots
from mission.procs.atomic import write_text_atomically

SNAPSHOT_EVERY = 20  # cycles between snapshots of G
ENDS = ("initial", "final")


class RunRecords:
    """The per-cycle record and G's snapshots, written as the run goes (flushed each cycle).

    ``g_snapshots``: ``every`` (the start, every SNAPSHOT_EVERY cycles and the end: what the
    3-D view replays), ``ends`` (the start and the end: what G learned) or ``none``."""

    def __init__(self, out_dir: Path, g_snapshots: GSnapshots = "every") -> None:
        if g_snapshots not in G_SNAPSHOTS:
            raise ValueError(f"g_snapshots must be one of {G_SNAPSHOTS}, not {g_snapshots!r}")
        self.out_dir = out_dir
        self.g_snapshots = g_snapshots
        self._records = (out_dir / "records.jsonl").open("w", encoding="utf-8")
        self._snapshots = out_dir / "g"
        if g_snapshots != "none":
            self._snapshots.mkdir(exist_ok=True)

    def cycle(
        self,
        state: StationState,
        output: CycleOutput,
        time_s: float,
        ages_ms: dict[str, list[float | None]] | None = None,
    ) -> None:
        """One line: the estimates, S, beta_n, arrival, G's update and each MPC's solve (with
        its predicted path V_n, U positions); in real time also the age of each support's
        [GNSS fix, camera observation] used (ms; None where missing). In lockstep every age is
        zero and the field is left out."""
        fusion = output.fusion
        record = {
            "t": round(time_s, 3),
            "k": state.k,
            "xhat": _rounded(state.xhat),
            "blind": output.blind,
            "fallback": fusion.fallback,
            "consistent": list(fusion.consistent),
            "contributing": list(fusion.contributing),
            "yhat": {n: _rounded(y) for n, y in state.yhat.items()},
            "beta": output.betas,
            "arrived": output.arrived,
            "g_updated_voxels": output.updated_voxels,
            "mpc": {
                n: {
                    "status": p.status,
                    "ms": round(p.solve_ms, 3),
                    "resolved": p.resolved,
                    "path": [_rounded(point) for point in p.path],
                }
                for n, p in output.support_plans.items()
            },
            "cycle_ms": round(output.cycle_ms, 3),
        }
        if output.own_fix is not None:  # roles.policy dynamic
            record["own_fix"] = output.own_fix.record()
        if state.allocation.supports:  # the supports have inspections of their own
            record["roles"] = state.allocation.record()
        if output.integrity is not None:  # integrity.enabled
            record["integrity"] = output.integrity.record()
        if ages_ms is not None:
            record["age_ms"] = ages_ms
        self._records.write(json.dumps(record) + "\n")
        self._records.flush()

    def snapshot(self, g: LocalizabilityMap, label: str) -> None:
        """G's values as ``g/G_<label>.npy`` (``initial``, ``final`` or a cycle count), if
        this run keeps that snapshot."""
        wanted = self.g_snapshots == "every" or (self.g_snapshots == "ends" and label in ENDS)
        if wanted:
            np.save(self._snapshots / f"G_{label}.npy", g.values)

    def link_stats(self, stats: dict[str, Any]) -> None:
        """``link.json``."""
        write_text_atomically(self.out_dir / "link.json", json.dumps(stats) + "\n")

    def close(self) -> None:
        """Close the records file."""
        self._records.close()


def _rounded(v: np.ndarray) -> list[float]:
    return [round(float(x), 4) for x in v]
