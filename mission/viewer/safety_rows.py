"""The margins in the view, at each control cycle whose truth has come: the closest approach
of any two UAVs and the least clearance of any UAV from the structure and the ground (plotted),
a red line between every pair closer than the separation margin, and a black marker at the
worst approach so far (the run's worst once it is over), as :mod:`mission.analysis.safety` counts
them at the cycles."""

from __future__ import annotations

import itertools

import numpy as np

from mission.viewer import frame as f
from mission.world.model import World
from mission.world.proximity import StructureProximity


class SafetyRows:
    """Per-cycle margin rows, from the cycles' true positions."""

    def __init__(self, world: World, names: list[str]) -> None:
        control = world.scenario.control
        self.separation = control.min_separation_m
        self.clearance = control.clearance_m
        self.names = names
        self.proximity = StructureProximity(world.structure)
        self.worst = np.inf

    def add(self, t: float, positions: dict[str, np.ndarray], out: f.Frame) -> None:
        """One cycle's rows from the true positions known at its time."""
        pairs = [
            (a, b, float(np.linalg.norm(positions[a] - positions[b])))
            for a, b in itertools.combinations(self.names, 2)
            if a in positions and b in positions
        ]
        if pairs:
            a, b, closest = min(pairs, key=lambda pair: pair[2])
            out.scalars[f.scalar_path("margins", "closest_approach")].add(t, closest)
            if closest < self.worst:
                self.worst = closest
                middle = (positions[a] + positions[b]) / 2
                out.points[f.WORST_PATH].add(t, middle, f.WORST_COLOUR)
        for a, b, distance in pairs:
            if distance < self.separation:
                line = np.vstack([positions[a], positions[b]])
                out.strips[f.below_margin_path(a, b)].add(t, line, f.BELOW_MARGIN_COLOUR)
        if positions:
            gaps = self.proximity.clearance(np.array(list(positions.values())))
            out.scalars[f.scalar_path("margins", "least_clearance")].add(t, float(gaps.min()))
