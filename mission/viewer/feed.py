"""A run's folder, read as it grows, into frames: the one path from files to rows that both
the replay (one read of a finished run) and the live view (a read every fraction of a second)
take, so they show the same thing."""

from __future__ import annotations

from pathlib import Path

from mission.config.settings import Scenario
from mission.viewer.assemble import RunAssembler
from mission.viewer.frame import Frame
from mission.viewer.map_rows import MapRows
from mission.viewer.scene import Scene, build_scene
from mission.viewer.tail import RecordsTail, TlogTail
from mission.world.model import World


class RunFeed:
    """The scene of a run's scenario and, frame by frame, what its files add."""

    def __init__(self, run_dir: Path, scenario: Scenario) -> None:
        world = World(scenario)
        self.scene: Scene = build_scene(scenario, world)
        self.assembler = RunAssembler(scenario, world, self.scene.waypoints)
        self.tlog = TlogTail(run_dir / "gcs.tlog")
        self.records = RecordsTail(run_dir / "records.jsonl")
        initial = world.sigma0_map().sigma_m.reshape(world.map_grid().shape)
        self.map = MapRows(run_dir / "g", initial)

    def read(self, final: bool) -> Frame:
        """What is new (``final``: the run is over; resolve everything left)."""
        frame = self.assembler.feed(self.tlog.read(), self.records.read(), final)
        frame.voxels.extend(self.map.read(self.assembler.cycles.times, final))
        return frame
