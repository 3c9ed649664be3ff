"""A finished run as data: its summary, and its trajectories, estimates, commands and fixes as
pandas DataFrames, read from the run's own files (``gcs.tlog``, ``records.jsonl``, ``g/``).

Every frame is long: one row per time and vehicle, positions in the world's ENU metres
(columns ``e``, ``n``, ``u``), times in simulated seconds (``t``). Vehicles are named as
everywhere else: ``work``, ``support-1``, ...
"""

from __future__ import annotations

import json
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from mission.api.summary import Summary
from mission.config.settings import Scenario

if TYPE_CHECKING:
    import pandas as pd

    from mission.analysis.trace import RunTrace

POSITION = ["e", "n", "u"]


def vehicle_name(system: int) -> str:
    """The vehicle of a MAVLink system id (1: the work UAV)."""
    return "work" if system == 1 else f"support-{system - 1}"


class Run:
    """A run's folder, read on demand (:func:`mission.load_run` or :func:`mission.run`)."""

    def __init__(self, path: Path, scenario: Scenario, summary: dict[str, Any]) -> None:
        self.path = Path(path)
        self.scenario = scenario
        self.summary = Summary.of(summary)

    def __repr__(self) -> str:
        s = self.summary
        done = f"completed at {s.completion_time_s} s" if s.completed else "not completed"
        return f"<Run {s.scenario} {s.method} seed {s.seed}: {done}, {self.path}>"

    @cached_property
    def trace(self) -> RunTrace:
        """The tlog read once (truth, estimates sent, setpoints, fixes)."""
        from mission.analysis.metrics import read_tlog

        return read_tlog(self.path / "gcs.tlog", self.scenario)

    def records(self) -> pd.DataFrame:
        """One row per control cycle from records.jsonl: ``t``, ``k`` (the waypoint index),
        ``blind``, ``fallback``, ``cycle_ms``, ``g_updated_voxels``, the work UAV's estimate
        (``xhat_e``, ``xhat_n``, ``xhat_u``), and the supports ``consistent`` (in S) and
        ``contributing`` (lists of names)."""
        import pandas as pd

        rows = []
        for record in self._records():
            xhat = record.get("xhat") or [np.nan] * 3
            rows.append(
                {
                    "t": record["t"],
                    "k": record.get("k"),
                    "blind": record.get("blind"),
                    "fallback": record.get("fallback"),
                    "cycle_ms": record.get("cycle_ms"),
                    "g_updated_voxels": record.get("g_updated_voxels"),
                    **{f"xhat_{axis}": value for axis, value in zip(POSITION, xhat)},
                    "consistent": list(record.get("consistent") or []),
                    "contributing": list(record.get("contributing") or []),
                }
            )
        return pd.DataFrame(rows)

    def estimates(self) -> pd.DataFrame:
        """The ground station's estimates each cycle, from records.jsonl: the work UAV's xhat
        and each support's yhat (``t``, ``vehicle``, ``e``, ``n``, ``u``), with a support's
        ``beta`` and whether it was in S (``in_s``; the work UAV's: NaN and None)."""
        import pandas as pd

        rows = []
        for record in self._records():
            if record.get("xhat") is not None:
                rows.append(_row(record["t"], "work", record["xhat"], beta=np.nan, in_s=None))
            consistent = set(record.get("consistent") or [])
            for name, yhat in (record.get("yhat") or {}).items():
                if yhat is not None:
                    beta = (record.get("beta") or {}).get(name)
                    beta = np.nan if beta is None else beta
                    rows.append(_row(record["t"], name, yhat, beta=beta, in_s=name in consistent))
        return pd.DataFrame(rows, columns=["t", "vehicle", *POSITION, "beta", "in_s"])

    def truth(self) -> pd.DataFrame:
        """Every vehicle's true position (SIM_STATE in the tlog): ``t``, ``vehicle``, ``e``,
        ``n``, ``u``."""
        return _frame(self.trace.truth)

    def commands(self) -> pd.DataFrame:
        """Every SET_POSITION_TARGET_LOCAL_NED the ground station sent: ``t``, ``vehicle``,
        ``e``, ``n``, ``u`` (the target)."""
        return _frame(self.trace.setpoints)

    def fixes(self) -> pd.DataFrame:
        """Every 3-D GNSS fix a vehicle reported (GPS_RAW_INT): ``t``, ``vehicle``, ``e``,
        ``n``, ``u``, and ``error_m``, its distance from the truth there (NaN unknown)."""
        frame = _frame(self.trace.fixes)
        errors = np.full(len(frame), np.nan)
        for system in {s for s, _ in self.trace.fixes}:
            mine = (frame["vehicle"] == vehicle_name(system)).to_numpy()
            truth, known = self.trace.truth_at(system, list(frame.loc[mine, "t"]))
            fixes = frame.loc[mine, POSITION].to_numpy()
            distance = np.full(len(fixes), np.nan)
            distance[known] = np.linalg.norm(fixes[known] - truth[known], axis=1)
            errors[mine] = distance
        frame["error_m"] = errors
        return frame

    def g_snapshots(self) -> list[str]:
        """The names of G's snapshots kept (``initial``, ``00020``, ..., ``final``)."""
        names = sorted(p.stem.removeprefix("G_") for p in (self.path / "g").glob("G_*.npy"))
        ordered = [n for n in ("initial",) if n in names] + [n for n in names if n.isdigit()]
        return ordered + [n for n in ("final",) if n in names]

    def g(self, snapshot: str | int = "final") -> np.ndarray:
        """G (sigma per voxel, metres, the map grid's shape) at ``snapshot``: ``initial``,
        ``final``, or the cycle count of a periodic one (``20``, ``40``, ...)."""
        name = f"{snapshot:05d}" if isinstance(snapshot, int) else snapshot
        path = self.path / "g" / f"G_{name}.npy"
        if not path.is_file():
            kept = ", ".join(self.g_snapshots()) or "none (run with g_snapshots='every')"
            raise KeyError(f"no snapshot {snapshot!r} of G in {self.path} (kept: {kept})")
        return np.load(path)

    def figures(self, out: str | Path | None = None) -> list[Path]:
        """Draw the run's figures (as ``mission analyze --plots``) into ``out`` (default: the
        run's ``plots/``); their paths."""
        from mission.analysis.run_plot import RunLabel, plot_run
        from mission.world.model import World

        out = Path(out) if out is not None else self.path / "plots"
        s = self.summary
        label = RunLabel(self.scenario.name, s.method, s.seed)
        return plot_run(self.trace, World(self.scenario), self.path / "g", out, label)

    def view(self, web: bool = False, save: str | Path | None = None) -> int:
        """Replay the run in 3-D, as ``mission view`` does: in a viewer (native, or the web
        viewer with ``web``), and/or into the recording ``save`` (.rrd) without one."""
        from mission.viewer.replay import replay_run, viewer_kind

        viewer = viewer_kind(web) if web or save is None else None
        return replay_run(self.path, self.scenario, viewer, Path(save) if save else None)

    def _records(self) -> list[dict[str, Any]]:
        path = self.path / "records.jsonl"
        with path.open(encoding="utf-8") as handle:
            return [json.loads(line) for line in handle if line.strip()]


def _row(t: float, vehicle: str, position, **more) -> dict[str, Any]:
    return {"t": t, "vehicle": vehicle, **dict(zip(POSITION, position)), **more}


def _frame(by_system_and_time: dict[tuple[int, float], np.ndarray]) -> pd.DataFrame:
    """A long frame of ``{(system, t): position}``, sorted by vehicle, then time."""
    import pandas as pd

    keys = sorted(by_system_and_time)
    rows = [_row(t, vehicle_name(system), by_system_and_time[(system, t)]) for system, t in keys]
    return pd.DataFrame(rows, columns=["t", "vehicle", *POSITION])
