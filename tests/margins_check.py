"""An independent check of the safety margins on the truth, for the tests and for a study's
runs: every vehicle's SIM_STATE read from the tlog by pymavlink, distances between UAVs at
their common samples by numpy, distances to the structure by trimesh.

    python -m tests.margins_check RUNS_DIR     # every run folder below RUNS_DIR, one line each

It shares nothing with ``mission.analysis.safety`` but the scenario file.
"""

from __future__ import annotations

import itertools
import os
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from mission.config.scenario import load_scenario
from mission.world.frames import GeodeticFrame
from mission.world.model import World


def independent_truth(tlog: Path, scenario) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Every vehicle's SIM_STATE with its step's SYSTEM_TIME stamp, read by pymavlink."""
    os.environ.setdefault("MAVLINK20", "1")
    from pymavlink import mavutil

    frame = GeodeticFrame(scenario.world.anchor)
    epoch = scenario.run.epoch_unix_s
    log = mavutil.mavlink_connection(str(tlog), dialect="ardupilotmega")
    pending, tracks = {}, {}
    while (message := log.recv_match(type=["SIM_STATE", "SYSTEM_TIME"])) is not None:
        source = message.get_srcSystem()
        if source == 255:
            continue
        if message.get_type() == "SIM_STATE":
            pending[source] = frame.from_degE7(message.lat_int, message.lon_int, message.alt)
        elif source in pending:
            t = round(message.time_unix_usec / 1e6 - epoch, 3)
            tracks.setdefault(source, {})[t] = pending.pop(source)
    return {
        s: (np.array(sorted(track)), np.array([track[t] for t in sorted(track)]))
        for s, track in tracks.items()
    }


@dataclass(frozen=True)
class Margins:
    """What one run's truth kept: the least distance between two UAVs and from a UAV to the
    structure or the ground, at the samples, and the margins it was flown with."""

    closest_approach_m: float
    least_clearance_m: float
    separation_m: float
    clearance_m: float
    radius_m: float

    @property
    def kept(self) -> bool:
        """No pair closer than the separation, no UAV closer than the clearance."""
        return (
            self.closest_approach_m >= self.separation_m
            and self.least_clearance_m >= self.clearance_m
        )


def run_margins(run_dir: Path, scenario_file: Path | str | None = None) -> Margins:
    """The margins one run's truth kept (its scenario: ``scenario_file``, else the run's own
    ``scenario.yaml``)."""
    scenario = load_scenario(str(scenario_file or run_dir / "scenario.yaml"))
    tracks = independent_truth(run_dir / "gcs.tlog", scenario)
    closest = np.inf
    for a, b in itertools.combinations(sorted(tracks), 2):
        times = np.intersect1d(tracks[a][0], tracks[b][0])
        pa = tracks[a][1][np.searchsorted(tracks[a][0], times)]
        pb = tracks[b][1][np.searchsorted(tracks[b][0], times)]
        closest = min(closest, float(np.linalg.norm(pa - pb, axis=1).min()))
    query = trimesh.proximity.ProximityQuery(World(scenario).structure.mesh)
    clearance = np.inf
    for _, positions in tracks.values():
        away = np.minimum(np.abs(query.signed_distance(positions)), positions[:, 2])
        clearance = min(clearance, float(away.min()))
    control = scenario.control
    return Margins(
        closest, clearance, control.min_separation_m, control.clearance_m, scenario.vehicle.radius_m
    )


def support_estimate_errors(run_dir: Path) -> np.ndarray:
    """(n, 3) each support's estimate yhat (records.jsonl) less its truth at the same cycle,
    over every cycle: what the margins' allowance for an estimate must cover."""
    import json

    scenario = load_scenario(str(run_dir / "scenario.yaml"))
    tracks = independent_truth(run_dir / "gcs.tlog", scenario)
    lines = (run_dir / "records.jsonl").read_text().splitlines()
    errors = []
    for record in map(json.loads, lines):
        for name, yhat in record["yhat"].items():
            times, positions = tracks[int(name.split("-")[1]) + 1]  # support-n is system n+1
            at = np.searchsorted(times, record["t"])
            if at < len(times) and times[at] == record["t"]:
                errors.append(np.asarray(yhat) - positions[at])
    return np.array(errors).reshape(-1, 3)


def main(argv: list[str]) -> int:
    """One line per run folder below ``argv[0]``, then the counts and the supports' estimate
    errors."""
    runs = sorted(p.parent for p in Path(argv[0]).glob("**/gcs.tlog"))
    results = {run.name: run_margins(run) for run in runs}
    for name, m in results.items():
        flag = "" if m.kept else "  BELOW A MARGIN"
        closest, clear = m.closest_approach_m, m.least_clearance_m
        print(f"{name}: closest {closest:.3f} m, clearance {clear:.3f} m{flag}")
    values = list(results.values())
    touching = sum(m.closest_approach_m < 2 * m.radius_m or m.least_clearance_m < m.radius_m
                   for m in values)  # fmt: skip
    print(
        f"{len(values)} runs: {sum(not m.kept for m in values)} below a margin "
        f"({sum(m.closest_approach_m < m.separation_m for m in values)} separation, "
        f"{sum(m.least_clearance_m < m.clearance_m for m in values)} clearance), "
        f"{touching} touching; least closest approach "
        f"{min(m.closest_approach_m for m in values):.3f} m, "
        f"least clearance {min(m.least_clearance_m for m in values):.3f} m"
    )
    errors = np.vstack([support_estimate_errors(run) for run in runs])
    std, worst = errors.std(axis=0), np.abs(errors).max(axis=0)
    print(
        f"support estimates, {len(errors)} cycles: error std x y z {std.round(3).tolist()} m, "
        f"largest {worst.round(3).tolist()} m, 99.9th percentile of the horizontal "
        f"{np.percentile(np.abs(errors[:, :2]), 99.9):.3f} m"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
